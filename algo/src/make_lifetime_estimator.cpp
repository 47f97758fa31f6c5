#include "evlife/algo/make_lifetime_estimator.h"

namespace evlife {

LifetimeEstimatorOrError make_lifetime_estimator(const LifetimeOptions& options) {
  LifetimeEstimatorOrError made;
  made.error = validate_lifetime_options(options);
  if (!made.error.empty()) {
    made.error.insert(0, "LifetimeOptions.");
    return made;
  }
  made.estimator.emplace(options);  // valid options: the constructor does not throw
  return made;
}

}  // namespace evlife
