#include <cmath>
#include <sstream>

#include "evlife/algo/lifetime_options.h"

namespace evlife {
namespace {
constexpr int kMaxSensorSide = 4096;

template <typename T>
bool in_range(T v, T lo, T hi) {
  return v >= lo && v <= hi;  // false for NaN
}
}  // namespace

std::string validate_lifetime_options(const LifetimeOptions& o) {
  std::ostringstream err;
  if (!in_range(o.sensor.width, 1, kMaxSensorSide) || !in_range(o.sensor.height, 1, kMaxSensorSide)) {
    err << "sensor: " << o.sensor.width << "x" << o.sensor.height << " is outside 1..4096 x 1..4096";
  } else if (!in_range(o.window_size, 3, 15) || o.window_size % 2 == 0) {
    err << "window_size: " << o.window_size << " must be odd, in 3..15";
  } else if (!(o.outlier_fraction > 0.0 && o.outlier_fraction <= 0.9)) {
    err << "outlier_fraction: " << o.outlier_fraction << " must be in (0, 0.9]";
  } else if (o.continuation_min_support != 0 &&
             !in_range(o.continuation_min_support, 2, (o.window_size * o.window_size - 1) / 2)) {
    err << "continuation_min_support: " << o.continuation_min_support
        << " must be 0 or in 2..(window_size^2 - 1)/2";
  } else if (!(o.ransac_confidence > 0.0 && o.ransac_confidence < 1.0)) {
    err << "ransac_confidence: " << o.ransac_confidence << " must be in (0, 1)";
  } else if (!(o.inlier_tolerance_us > 0.0 && o.inlier_tolerance_us <= 1e6)) {
    err << "inlier_tolerance_us: " << o.inlier_tolerance_us << " must be in (0, 1e6]";
  } else if (!(o.inlier_tolerance_lifetime_fraction > 0.0 &&
               o.inlier_tolerance_lifetime_fraction <= 0.5)) {
    err << "inlier_tolerance_lifetime_fraction: " << o.inlier_tolerance_lifetime_fraction
        << " must be in (0, 0.5]";
  } else if (!in_range(o.inlier_tolerance_residual_factor, 0.0, 10.0)) {
    err << "inlier_tolerance_residual_factor: " << o.inlier_tolerance_residual_factor << " must be in [0, 10]";
  } else if (!in_range(o.lambda_offset, 0.0, 1e9) || !in_range(o.lambda_gain, 0.0, 1e9)) {
    err << "lambda_offset/lambda_gain: " << o.lambda_offset << "/" << o.lambda_gain
        << " must be in [0, 1e9]";
  } else if (!in_range(o.lambda_unit_px2, 0.0, 1e6)) {
    err << "lambda_unit_px2: " << o.lambda_unit_px2 << " must be in [0, 1e6]";
  } else if (!in_range(o.lambda_decay_per_us, 0.0, 1e3)) {
    err << "lambda_decay_per_us: " << o.lambda_decay_per_us << " must be in [0, 1000]";
  } else if (!in_range(o.burst_window_lifetimes, 0.0, 10.0)) {
    err << "burst_window_lifetimes: " << o.burst_window_lifetimes << " must be in [0, 10]";
  } else if (!(o.max_lifetime_us > 0.0 && o.max_lifetime_us <= 1e9)) {
    err << "max_lifetime_us: " << o.max_lifetime_us << " must be in (0, 1e9]";
  }
  return err.str();
}

}  // namespace evlife
