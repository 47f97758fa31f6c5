// Keys of the `estimator:` section, 1:1 with evlife::LifetimeOptions.
// Ranges match validate_lifetime_options(), which build() also runs.
#include "key_helpers.h"

namespace evlife::config::detail {

void add_estimator_keys(std::vector<ConfigKey>& keys) {
  using D = Range<double>;
  keys.push_back(number_key<int>(
      "estimator.sensor.width", [](auto& c) -> auto& { return c.estimator.sensor.width; },
      Range<int>{1, 4096}));
  keys.push_back(number_key<int>(
      "estimator.sensor.height", [](auto& c) -> auto& { return c.estimator.sensor.height; },
      Range<int>{1, 4096}));
  keys.push_back(number_key<int>(
      "estimator.window_size", [](auto& c) -> auto& { return c.estimator.window_size; },
      Range<int>{3, 15, false, false, true}));
  keys.push_back(number_key<double>(
      "estimator.outlier_fraction", [](auto& c) -> auto& { return c.estimator.outlier_fraction; },
      D{0.0, 0.9, true, false}));
  keys.push_back(number_key<double>(
      "estimator.ransac_confidence", [](auto& c) -> auto& { return c.estimator.ransac_confidence; },
      D{0.0, 1.0, true, true}));
  keys.push_back(number_key<double>(
      "estimator.inlier_tolerance_us",
      [](auto& c) -> auto& { return c.estimator.inlier_tolerance_us; }, D{0.0, 1e6, true, false}));
  keys.push_back(number_key<double>(
      "estimator.inlier_tolerance_lifetime_fraction",
      [](auto& c) -> auto& { return c.estimator.inlier_tolerance_lifetime_fraction; },
      D{0.0, 0.5, true, false}));
  keys.push_back(number_key<double>(
      "estimator.inlier_tolerance_residual_factor",
      [](auto& c) -> auto& { return c.estimator.inlier_tolerance_residual_factor; }, D{0.0, 10.0}));
  keys.push_back(bool_key("estimator.regularization",
                          [](auto& c) -> auto& { return c.estimator.regularization; }));
  keys.push_back(number_key<double>(
      "estimator.lambda_offset", [](auto& c) -> auto& { return c.estimator.lambda_offset; },
      D{0.0, 1e9}));
  keys.push_back(number_key<double>(
      "estimator.lambda_gain", [](auto& c) -> auto& { return c.estimator.lambda_gain; },
      D{0.0, 1e9}));
  keys.push_back(number_key<double>(
      "estimator.lambda_decay_per_us",
      [](auto& c) -> auto& { return c.estimator.lambda_decay_per_us; }, D{0.0, 1e3}));
  keys.push_back(number_key<double>(
      "estimator.lambda_unit_px2", [](auto& c) -> auto& { return c.estimator.lambda_unit_px2; },
      D{0.0, 1e6}));
  keys.push_back(number_key<int>(
      "estimator.continuation_min_support", [](auto& c) -> auto& { return c.estimator.continuation_min_support; },
      Range<int>{0, 112}));
  keys.push_back(number_key<double>(
      "estimator.burst_window_lifetimes",
      [](auto& c) -> auto& { return c.estimator.burst_window_lifetimes; }, D{0.0, 10.0}));
  keys.push_back(number_key<double>(
      "estimator.max_lifetime_us", [](auto& c) -> auto& { return c.estimator.max_lifetime_us; },
      D{0.0, 1e9, true, false}));
  keys.push_back(number_key<std::uint64_t>(
      "estimator.seed", [](auto& c) -> auto& { return c.estimator.seed; },
      Range<std::uint64_t>{0, std::numeric_limits<std::uint64_t>::max()}));
}

}  // namespace evlife::config::detail
