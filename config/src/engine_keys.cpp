// Keys of the `engine:` section (evlife run), 1:1 with EngineSection; the
// ranges match evlife::engine::validate_engine_options().
#include "key_helpers.h"

namespace evlife::config::detail {

void add_engine_keys(std::vector<ConfigKey>& keys) {
  keys.push_back(number_key<int>(
      "engine.workers", [](auto& c) -> auto& { return c.engine.workers; }, Range<int>{1, 32}));
  keys.push_back(number_key<int>(
      "engine.tiles_x", [](auto& c) -> auto& { return c.engine.tiles_x; }, Range<int>{1, 256}));
  keys.push_back(number_key<int>(
      "engine.tiles_y", [](auto& c) -> auto& { return c.engine.tiles_y; }, Range<int>{1, 256}));
  keys.push_back(number_key<int>(
      "engine.margin_px", [](auto& c) -> auto& { return c.engine.margin_px; },
      Range<int>{-1, 1024}));
  keys.push_back(number_key<int>(
      "engine.batch_events", [](auto& c) -> auto& { return c.engine.batch_events; },
      Range<int>{16, 65536}));
  keys.push_back(number_key<int>(
      "engine.batches_per_worker", [](auto& c) -> auto& { return c.engine.batches_per_worker; },
      Range<int>{2, 1024}));
  keys.push_back(string_key("engine.policy", [](auto& c) -> auto& { return c.engine.policy; },
                            {"auto", "block", "drop"}));
  keys.push_back(number_key<double>(
      "engine.stats_period_s", [](auto& c) -> auto& { return c.engine.stats_period_s; },
      Range<double>{0.0, 3600.0}));
  keys.push_back(number_key<int>(
      "engine.idle_spin_us", [](auto& c) -> auto& { return c.engine.idle_spin_us; },
      Range<int>{-1, 100000}));
  keys.push_back(number_key<int>(
      "engine.replay_packet_us", [](auto& c) -> auto& { return c.engine.replay_packet_us; },
      Range<int>{0, 1000000}));
}

}  // namespace evlife::config::detail
