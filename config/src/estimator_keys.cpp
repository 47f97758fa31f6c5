// Keys of the `estimator:` section: one per entry of the table next to
// evlife::LifetimeOptions (for_each_lifetime_option), whose ranges
// validate_lifetime_options() checks too.
#include "key_helpers.h"

namespace evlife::config::detail {

void add_estimator_keys(std::vector<ConfigKey>& keys) {
  add_table_keys(keys, "estimator", &Config::estimator, [](auto&& f) { for_each_lifetime_option(f); });
  // Its table range is the widest window's; the rule is the window's own
  // (validate_lifetime_options): the allowed text says the rule, not [0, 112].
  for (ConfigKey& k : keys)
    if (k.name == "estimator.continuation_min_support") k.allowed = "0 or 2..(N^2-1)/2, N = window_size";
}

}  // namespace evlife::config::detail
