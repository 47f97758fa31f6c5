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
// biased short (pixel model, dim light, lifetimes below 500 us: median
// -24 %; test CensoredRefit.RemovesMostOfTheBiasThatCausalityCausesInDimLight).
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
  bool resolved = true;   ///< the lifetime's standard error is at most max_share of it (or cannot be told)
  double lifetime_us = 0.0;
};

// The least-squares slope of dt over s from the sums, with the prior; the
// sums of squares multiplied by n so that one division remains.
inline CensoredRefit finish_censored_refit(double n, double ss, double st, double sss, double sst, double stt,
                                           double lambda, double prior_lifetime_us, double min_spread_px2,
                                           double max_share) noexcept {
  const double spread_n = n * sss - ss * ss;  // n x the spread along the motion, px^2
  if (!(spread_n >= min_spread_px2 * n)) return {};
  const double cov_n = n * sst - ss * st;
  const double weight_n = spread_n + n * lambda;
  CensoredRefit out;
  out.refitted = true;
  const double tau = (cov_n + n * lambda * prior_lifetime_us) / weight_n;
  out.lifetime_us = tau;
  if (n > 2.0 && max_share > 0.0) {
    // variance = sse / (n - 2) / (spread + lambda) <= (max_share tau)^2, with
    // sse = (n stt - st^2 - 2 tau cov_n + tau^2 spread_n) / n.
    const double sse_n = std::max((n * stt - st * st) - 2.0 * tau * cov_n + tau * tau * spread_n, 0.0);
    out.resolved = sse_n <= max_share * max_share * tau * tau * (n - 2.0) * weight_n;
  }
  return out;
}

/// Fits dt = c + tau * s, s = (ux, uy) . dp the position along the motion
/// (px), to the new event (s = 0, dt = 0) and the RANSAC inliers of `nb`
/// (within sqrt(tol2_us2) of dt = gx * dx + gy * dy, as the plane fit takes
/// them) that the plane (lifetime_us along (ux, uy)) puts more than censor_us
/// before the new event. The prior lifetime (the predicted gradient along
/// the motion) enters with weight lambda as in the plane fit (eq. 12).
/// `resolved`: its standard error is at most max_share of it (0: no check).
/// Not refitted when the samples spread less than 1 px^2 along the motion.
/// Defined in censored_refit.cpp (on x86-64 also compiled for AVX2, chosen
/// at load time: the same operations in the same order, the same bits).
CensoredRefit refit_without_censored(const WindowSamples& nb, float gx, float gy, float tol2_us2, double ux, double uy,
                                     double lifetime_us, double censor_us, double lambda, double prior_lifetime_us,
                                     double max_share) noexcept;

}  // namespace evlife::detail
