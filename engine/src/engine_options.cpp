#include "evlife/engine/engine_options.h"

#include "evlife/engine/tile_layout.h"

namespace evlife::engine {

int effective_margin_px(const EngineOptions& options) {
  if (options.tiles_x == 1 && options.tiles_y == 1) return 0;  // tiles = whole polarities
  if (options.margin_px >= 0) return options.margin_px;
  return 4 * options.lifetime.window_size;
}

int effective_idle_spin_us(const EngineOptions& options, bool live_source) {
  if (options.idle_spin_us >= 0) return options.idle_spin_us;
  return live_source ? kAutoIdleSpinUs : 0;
}

std::string validate_engine_options(const EngineOptions& o) {
  if (std::string rt = validate_realtime_options(o.realtime); !rt.empty()) return rt;
  if (o.workers < 1 || o.workers > TileLayout::kMaxWorkers)
    return "engine.workers: must be 1..32 (got " + std::to_string(o.workers) + ")";
  if (o.tiles_x < 1 || o.tiles_x > 256)
    return "engine.tiles_x: must be 1..256 (got " + std::to_string(o.tiles_x) + ")";
  if (o.tiles_y < 1 || o.tiles_y > 256)
    return "engine.tiles_y: must be 1..256 (got " + std::to_string(o.tiles_y) + ")";
  if (o.margin_px < -1 || o.margin_px > 1024)
    return "engine.margin_px: must be -1 (auto) or 0..1024 (got " +
           std::to_string(o.margin_px) + ")";
  if (o.batch_events < 16 || o.batch_events > 65536)
    return "engine.batch_events: must be 16..65536 (got " + std::to_string(o.batch_events) + ")";
  if (o.batches_per_worker < 2 || o.batches_per_worker > 1024)
    return "engine.batches_per_worker: must be 2..1024 (got " +
           std::to_string(o.batches_per_worker) + ")";
  if (o.render_batches > 1024)
    return "engine.render_batches: must be 0..1024 (got " + std::to_string(o.render_batches) + ")";
  if (o.idle_spin_us < -1 || o.idle_spin_us > 100000)
    return "engine.idle_spin_us: must be -1 (auto) or 0..100000 (got " +
           std::to_string(o.idle_spin_us) + ")";
  if (!(o.stats_period_s >= 0.0))
    return "engine.stats_period_s: must be >= 0";
  return {};
}

}  // namespace evlife::engine
