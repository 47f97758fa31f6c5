// Options of the lifetime estimator (paper Section III). A plain struct with
// defaults; validate it with validate_lifetime_options() or by constructing a
// LifetimeEstimator, which throws std::invalid_argument naming the field.
#pragma once

#include <cstdint>
#include <string>

#include "evlife/algo/event.h"

namespace evlife {

struct LifetimeOptions {
  /// Sensor size in pixels. 1..4096 each way.
  SensorSize sensor{128, 128};

  /// N: side of the square window around the new event, odd, 3..15.
  /// Larger N: more support, smoother velocity, more cost (O(N^2)).
  int window_size = 5;

  /// epsilon: expected share of outliers among the window's newer half.
  /// Sets the RANSAC iteration count (for ransac_confidence) and the minimum
  /// support m = (1 - epsilon) * N^2 / 2 (paper eq. 8). In (0, 0.9].
  double outlier_fraction = 0.4;

  /// Probability that RANSAC draws at least one all-inlier sample. (0, 1).
  double ransac_confidence = 0.99;

  /// Inlier tolerance, microseconds: a past event supports a candidate plane
  /// when its timestamp is within this of the plane's time at its pixel.
  /// Must exceed the timestamp jitter and stay below about a third of the
  /// shortest lifetime of interest, or stale events fit steep planes and
  /// noise passes as edges. (0, 1e6].
  double inlier_tolerance_us = 100.0;

  /// Regularize the least-squares plane towards the plane predicted for this
  /// pixel by an earlier event (paper eq. 12).
  bool regularization = true;

  /// lambda(dt_err) = lambda_offset + lambda_gain * exp(-lambda_decay_per_us * dt_err)
  /// (paper eq. 13); dt_err in microseconds; lambda in px^2 (it weighs a
  /// gradient difference in us/px against time residuals in us).
  double lambda_offset = 9.0;
  double lambda_gain = 100.0;
  double lambda_decay_per_us = 0.005;

  /// Lifetimes above this are treated as noise (a near-vertical plane fitted
  /// through stale events is not an edge). Microseconds, > 0.
  double max_lifetime_us = 1.0e6;

  /// Seed of the RANSAC sampler. Each event draws from a generator seeded by
  /// (seed, x, y, t, p), so results do not depend on processing order.
  std::uint64_t seed = 0x5eed;
};

/// Returns an empty string when the options are usable, else a message that
/// names the offending field and its allowed range. Never throws.
std::string validate_lifetime_options(const LifetimeOptions& options);

}  // namespace evlife
