// The non-throwing way to build a LifetimeEstimator, for code built without
// exceptions (-fno-exceptions -fno-rtti: PX4, many ROS 2 and RTOS builds).
// The options are validated first; invalid options give an error naming the
// field and its allowed range instead of an estimator.
//
//   auto made = evlife::make_lifetime_estimator(options);
//   if (!made) { report(made.error); return; }    // "LifetimeOptions.window_size: 4 must be odd, in [3, 15]"
//   evlife::LifetimeEstimator& estimator = *made.estimator;
//
// LifetimeEstimator's constructor stays as it is: it throws
// std::invalid_argument on invalid options, or, in a build without
// exceptions, aborts (so call this factory there).
#pragma once

#include <optional>
#include <string>

#include "evlife/algo/lifetime_estimator.h"
#include "evlife/algo/lifetime_options.h"

namespace evlife {

/// Either an estimator (error empty) or the reason there is none.
struct LifetimeEstimatorOrError {
  std::optional<LifetimeEstimator> estimator;
  /// Empty when `estimator` holds a value; else "LifetimeOptions.<field>: ...",
  /// the message the throwing constructor would have carried.
  std::string error;
  explicit operator bool() const noexcept { return estimator.has_value(); }
};

/// Validates `options` and, when they are usable, builds the estimator
/// (allocating its per-pixel state). Never throws for invalid options; running
/// out of memory is as for any allocation (std::bad_alloc, or abort in a
/// build without exceptions).
LifetimeEstimatorOrError make_lifetime_estimator(const LifetimeOptions& options);

}  // namespace evlife
