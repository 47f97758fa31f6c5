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
}  // namespace

TileLayout::TileLayout(SensorSize sensor, int workers, int tiles_x, int tiles_y, int margin_px)
    : sensor_(sensor), workers_(workers), tiles_x_(tiles_x), tiles_y_(tiles_y),
      margin_px_(margin_px) {
  if (sensor.width < 1 || sensor.height < 1 || sensor.width > 65535 || sensor.height > 65535)
    throw std::invalid_argument("sensor: size must be 1..65535 each way");
  if (workers < 1 || workers > kMaxWorkers)
    throw std::invalid_argument("workers: must be 1.." + std::to_string(kMaxWorkers));
  if (tiles_x < 1 || tiles_x > sensor.width)
    throw std::invalid_argument("tiles_x: must be 1..sensor width");
  if (tiles_y < 1 || tiles_y > sensor.height)
    throw std::invalid_argument("tiles_y: must be 1..sensor height");
  if (margin_px < 0) throw std::invalid_argument("margin_px: must be >= 0");

  const std::size_t plane = static_cast<std::size_t>(sensor.pixel_count());
  owner_.assign(2 * plane, 0);
  feed_.assign(2 * plane, 0);
  for (int pi = 0; pi < 2; ++pi) {
    for (int row = 0; row < tiles_y; ++row) {
      for (int col = 0; col < tiles_x; ++col) {
        const int w = tile_owner(pi, col, row);
        const int x0 = tile_begin(col, tiles_x, sensor.width);
        const int x1 = tile_begin(col + 1, tiles_x, sensor.width);
        const int y0 = tile_begin(row, tiles_y, sensor.height);
        const int y1 = tile_begin(row + 1, tiles_y, sensor.height);
        for (int y = y0; y < y1; ++y)
          for (int x = x0; x < x1; ++x)
            owner_[(static_cast<std::size_t>(pi) * sensor.height + y) * sensor.width + x] =
                static_cast<std::uint8_t>(w);
        // The tile grown by the margin, clipped to the sensor: fed to w.
        const int fx0 = std::max(0, x0 - margin_px), fx1 = std::min(sensor.width, x1 + margin_px);
        const int fy0 = std::max(0, y0 - margin_px), fy1 = std::min(sensor.height, y1 + margin_px);
        for (int y = fy0; y < fy1; ++y)
          for (int x = fx0; x < fx1; ++x)
            feed_[(static_cast<std::size_t>(pi) * sensor.height + y) * sensor.width + x] |=
                1u << w;
      }
    }
  }
}

int TileLayout::tile_owner(int polarity_index, int tile_col, int tile_row) const noexcept {
  const int tile = (polarity_index * tiles_y_ + tile_row) * tiles_x_ + tile_col;
  return tile % workers_;
}

}  // namespace evlife::engine
