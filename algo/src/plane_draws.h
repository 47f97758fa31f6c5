// RANSAC's draws (LifetimeEstimator::best_plane()): candidate planes through
// the new event and two window samples drawn at random, scored by how many
// samples they hold.
#pragma once

#include <algorithm>

#include "event_rng.h"
#include "window_samples.h"

namespace evlife::detail {

/// A plane dt = gx*dx + gy*dy through the new event (the origin); support:
/// the samples within sqrt(tol2_us2) of it, and the origin.
struct PlaneCandidate {
  int support = 0;
  float gx_us_px = 0.0f, gy_us_px = 0.0f, tol2_us2 = 0.0f;
};

/// The plane (gx, gy) as a candidate: its squared tolerance max(tol_floor2,
/// tol_fraction2 x |g|^2) and its support in `w` (pad() called).
inline PlaneCandidate plane_candidate(const WindowSamples& w, float gx, float gy, float tol_floor2,
                                      float tol_fraction2) noexcept {
  const float tol2 = std::max(tol_floor2, tol_fraction2 * (gx * gx + gy * gy));
  return {1 + w.support(gx, gy, tol2), gx, gy, tol2};  // + the origin
}

/// Up to `iterations` planes through the origin and two samples of `w`
/// (pad() called) drawn with `rng`, none where the two are collinear with
/// the origin; tolerance max(tol_floor2, tol_fraction2 x |g|^2). One with
/// more support than `best` replaces it and cuts the iterations to
/// budget[its support - 1] (budget[inliers]: the iterations needed with that
/// many inliers among w.count; w.count + 1 entries, 17 readable). Defined in
/// plane_draws.cpp, on x86-64 also for AVX2 (chosen at load time: the same
/// float operations on the same values, the same choice, the same draws).
PlaneCandidate best_of_draws(const WindowSamples& w, EventRng& rng, int iterations, const int* budget,
                             float tol_floor2, float tol_fraction2, PlaneCandidate best) noexcept;

}  // namespace evlife::detail
