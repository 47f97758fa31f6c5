// Keys of the `estimator:` section: one per entry of the table next to
// evlife::LifetimeOptions (for_each_lifetime_option), whose ranges
// validate_lifetime_options() checks too.
#include "key_helpers.h"

namespace evlife::config::detail {

void add_estimator_keys(std::vector<ConfigKey>& keys) {
  add_table_keys(keys, "estimator", &Config::estimator, [](auto&& f) { for_each_lifetime_option(f); });
}

}  // namespace evlife::config::detail
