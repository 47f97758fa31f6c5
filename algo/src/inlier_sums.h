// The refit's sums over RANSAC's inliers, four samples at a time (the fast
// path of PlaneFit::add_inliers()). Defined in inlier_sums.cpp, on x86-64
// also compiled for AVX2 and chosen at load time: the sums are exact
// integers (see add_inliers()), the same whichever version runs.
#pragma once

#include "window_samples.h"

namespace evlife::detail {

/// Per-lane-pair sums of the inliers: each field is (lane 0 + lane 1) +
/// (lane 2 + lane 3) of four lanes that take samples k = lane mod 4.
struct InlierSums {
  double n, sx, sy, st, sxx, sxy, syy, sxt, syt, stt;
};

/// The inliers of nb (pad() called) within sqrt(tol2_us2) of the plane
/// dt = gx*dx + gy*dy, summed into `sums`; false (sums unset) when some
/// sample's |dt| exceeds 2^21 us, where the sums might not be exact.
bool exact_inlier_sums(const WindowSamples& nb, float gx, float gy, float tol2_us2, InlierSums& sums) noexcept;

}  // namespace evlife::detail
