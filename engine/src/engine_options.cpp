#include "evlife/engine/engine_options.h"

#include <fmt/format.h>

#include "evlife/engine/tile_layout.h"

namespace evlife::engine {

int effective_margin_px(const EngineOptions& options) {
  if (options.tiles_x == 1 && options.tiles_y == 1) return 0;  // tiles = whole polarities
  if (options.margin_px >= 0) return options.margin_px;
  return 4 * options.lifetime.window_size;
}

int effective_idle_spin_us(const EngineOptions& options, bool live_source) {
  if (options.idle_spin_us >= 0) return options.idle_spin_us;
  // SCHED_FIFO threads that poll keep their cores from every other task
  // (sched_yield yields only to their own priority) until the kernel's RT
  // throttling stops them for the rest of its period: ~50 ms a second, 8 %
  // of a run dropped. A FIFO thread's wake-up preempts at once anyway.
  if (options.realtime.rt_priority > 0) return 0;
  return live_source ? kAutoIdleSpinUs : 0;
}

std::string validate_engine_options(const EngineOptions& o) {
  if (std::string rt = validate_realtime_options(o.realtime); !rt.empty()) return rt;
  std::string err;
  for_each_engine_option([&](const OptionInfo& info, auto field) {
    if (err.empty() && !info.contains(static_cast<double>(field(o))))
      err = "engine." + check_option(info, field(o));
  });
  if (!err.empty()) return err;
  if (const auto problem = stats_period_problem(o.stats_period_s))
    return "engine.stats_period_s: " + fmt::format("{:g}", o.stats_period_s) + " " + *problem;
  static_assert(TileLayout::kMaxWorkers == 32, "engine.workers' range in engine_options.h");
  if (o.render_batches > 1024)
    return "engine.render_batches: must be 0..1024 (got " + std::to_string(o.render_batches) + ")";
  return {};
}

}  // namespace evlife::engine
