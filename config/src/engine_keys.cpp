// Keys of the `engine:` section (evlife run): one per entry of the table next
// to evlife::engine::EngineOptions (for_each_engine_option), whose ranges
// validate_engine_options() checks too; plus the overload policy.
#include "key_helpers.h"

namespace evlife::config::detail {

void add_engine_keys(std::vector<ConfigKey>& keys) {
  add_table_keys(keys, "engine", &Config::engine, [](auto&& f) { engine::for_each_engine_option(f); });
  ConfigKey policy;
  policy.name = "engine." + std::string(engine::kPolicyKey);
  policy.type = "string";
  policy.allowed = "one of: auto, block, drop";
  policy.doc = "when workers lag: auto (block files, drop cameras), block or drop";
  policy.parse = [](Config& c, std::string_view text) {
    return engine::parse_overload_policy(text, c.engine.auto_policy, c.engine.policy);
  };
  policy.in_range = [](const Config&) { return true; };
  policy.format = [](const Config& c) {
    return std::string(engine::overload_policy_name(c.engine.auto_policy, c.engine.policy));
  };
  keys.push_back(std::move(policy));
}

}  // namespace evlife::config::detail
