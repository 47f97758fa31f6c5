// The lifetime re-estimated along the fitted motion without the samples that
// causality censors.
//
// Only past events are samples, and of them only the newer half of the
// window (paper Fig. 6): both select on the timestamps. A pixel the edge
// reaches about now (the plane puts it less than the timing noise before
// the new event), or after it, is a sample only if its latency jitter was
// early; the late ones are not in the window yet, or not among the newer
// half. The samples that are there pull the plane flat: where the jitter
// approaches the lifetime (dim light, fast edges) the plane fit's lifetime is
// biased short (pixel model, dim light, lifetimes below 400 us: median
// -30 %; test CensoredRefit.RemovesMostOfTheBiasThatCausalityCausesInDimLight).
// Leaving them out of a 2-D refit leaves the rest on a line across the motion
// too often (the along-edge gradient is then free), so the direction stays
// the plane fit's and only the slope along it is refitted.
#pragma once

#include <algorithm>
#include <cmath>

#include "window_samples.h"

namespace evlife::detail {

struct CensoredRefit {
  bool refitted = false;  ///< false: too few uncensored samples along the motion
  double lifetime_us = 0.0;
  double variance_us2 = -1.0;  ///< the lifetime's squared standard error; -1: too few samples to tell
};

// The least-squares slope of dt over s from the sums, with the prior.
inline CensoredRefit finish_censored_refit(double n, double ss, double st, double sss, double sst, double stt,
                                           double lambda, double prior_lifetime_us, double min_spread_px2) noexcept {
  const double inv_n = 1.0 / n;
  const double spread = sss - ss * ss * inv_n;
  if (!(spread >= min_spread_px2)) return {};
  const double cov = sst - ss * st * inv_n;
  const double inv_weight = 1.0 / (spread + lambda);
  CensoredRefit out;
  out.refitted = true;
  out.lifetime_us = (cov + lambda * prior_lifetime_us) * inv_weight;
  if (n > 2.0) {
    const double sse = (stt - st * st * inv_n) - 2.0 * out.lifetime_us * cov + out.lifetime_us * out.lifetime_us * spread;
    out.variance_us2 = std::max(sse, 0.0) / (n - 2.0) * inv_weight;
  }
  return out;
}

/// Fits dt = c + tau * s, s = (ux, uy) . dp the position along the motion
/// (px), to the new event (s = 0, dt = 0) and the RANSAC inliers of `nb`
/// (within sqrt(tol2_us2) of dt = gx * dx + gy * dy, as the plane fit takes
/// them) that the plane (lifetime_us along (ux, uy)) puts more than censor_us
/// before the new event. The prior lifetime (the predicted gradient along
/// the motion) enters with weight lambda as in the plane fit (eq. 12).
/// Not refitted when the samples spread less than 1 px^2 along the motion.
/// Defined in censored_refit.cpp (on x86-64 also compiled for AVX2, chosen
/// at load time: the same operations in the same order, the same bits).
CensoredRefit refit_without_censored(const WindowSamples& nb, float gx, float gy, float tol2_us2, double ux, double uy,
                                     double lifetime_us, double censor_us, double lambda,
                                     double prior_lifetime_us) noexcept;

}  // namespace evlife::detail
