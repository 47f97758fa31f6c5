// Validation reads the one table of ranges (for_each_lifetime_option) and
// adds the rules that tie two fields together.
#include "evlife/algo/lifetime_options.h"

namespace evlife {

std::string validate_lifetime_options(const LifetimeOptions& o) {
  std::string err;
  for_each_lifetime_option([&](const OptionInfo& info, auto field) {
    if (err.empty()) err = check_option(info, field(o));
  });
  if (!err.empty()) return err;
  const int max_support = (o.window_size * o.window_size - 1) / 2;
  if (o.continuation_min_support != 0 &&
      (o.continuation_min_support < 2 || o.continuation_min_support > max_support)) {
    return "continuation_min_support: " + std::to_string(o.continuation_min_support) +
           " must be 0 or in 2..(window_size^2 - 1)/2 = " + std::to_string(max_support);
  }
  return {};
}

}  // namespace evlife
