#include "evlife/engine/tile_layout.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace evlife::engine {
namespace {
// Tile c of n over `extent` pixels covers [c*extent/n, (c+1)*extent/n).
int tile_begin(int c, int n, int extent) {
  return static_cast<int>(static_cast<long long>(c) * extent / n);
}

// For each pixel coordinate: its tile, and the range of tiles whose extent
// grown by `margin` contains it (contiguous: grown extents are ordered).
template <typename SpanT>
void fill_axis(int extent, int tiles, int margin, std::vector<std::uint16_t>& tile_of,
               std::vector<SpanT>& feed) {
  tile_of.assign(static_cast<std::size_t>(extent), 0);
  feed.assign(static_cast<std::size_t>(extent), SpanT{0xFFFF, 0});
  for (int t = 0; t < tiles; ++t) {
    const int b = tile_begin(t, tiles, extent), e = tile_begin(t + 1, tiles, extent);
    for (int i = b; i < e; ++i) tile_of[static_cast<std::size_t>(i)] = static_cast<std::uint16_t>(t);
    for (int i = std::max(0, b - margin); i < std::min(extent, e + margin); ++i) {
      SpanT& s = feed[static_cast<std::size_t>(i)];
      s.first = std::min<std::uint16_t>(s.first, static_cast<std::uint16_t>(t));
      s.last = std::max<std::uint16_t>(s.last, static_cast<std::uint16_t>(t));
    }
  }
}
}  // namespace

TileLayout::TileLayout(SensorSize sensor, int workers, int tiles_x, int tiles_y, int margin_px)
    : sensor_(sensor), workers_(workers), tiles_x_(tiles_x), tiles_y_(tiles_y),
      margin_px_(margin_px) {
  if (sensor.width < 1 || sensor.height < 1 || sensor.width > 65535 || sensor.height > 65535)
    throw std::invalid_argument("sensor: size must be 1..65535 each way");
  if (workers < 1 || workers > kMaxWorkers)
    throw std::invalid_argument("workers: must be 1.." + std::to_string(kMaxWorkers));
  if (tiles_x < 1 || tiles_x > sensor.width || tiles_x > 4096)
    throw std::invalid_argument("tiles_x: must be 1..min(sensor width, 4096)");
  if (tiles_y < 1 || tiles_y > sensor.height || tiles_y > 4096)
    throw std::invalid_argument("tiles_y: must be 1..min(sensor height, 4096)");
  if (margin_px < 0) throw std::invalid_argument("margin_px: must be >= 0");

  fill_axis(sensor.width, tiles_x, margin_px, col_of_x_, feed_cols_);
  fill_axis(sensor.height, tiles_y, margin_px, row_of_y_, feed_rows_);
  // Tiles dealt round robin, polarity-major.
  tile_worker_.resize(2 * static_cast<std::size_t>(tiles_x) * static_cast<std::size_t>(tiles_y));
  for (std::size_t i = 0; i < tile_worker_.size(); ++i)
    tile_worker_[i] = static_cast<std::uint8_t>(i % static_cast<std::size_t>(workers));
  const auto one_tile = [](const auto& spans) {
    return std::all_of(spans.begin(), spans.end(), [](const Span& s) { return s.first == s.last; });
  };
  owner_only_ = one_tile(feed_cols_) && one_tile(feed_rows_);
}

}  // namespace evlife::engine
