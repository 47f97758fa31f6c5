// Keys of the `estimator:` section: one per entry of the table next to
// evlife::LifetimeOptions (for_each_lifetime_option), whose ranges
// validate_lifetime_options() checks too.
#include "key_helpers.h"

namespace evlife::config::detail {

void add_estimator_keys(std::vector<ConfigKey>& keys) {
  for_each_lifetime_option([&](const OptionInfo& info, auto field) {
    keys.push_back(table_key("estimator", info,
                             [field](auto& c) -> auto& { return field(c.estimator); }));
  });
}

}  // namespace evlife::config::detail
