// Which worker owns each (polarity, pixel), and which workers must be fed it
// (the owner plus every worker whose tiles lie within the margin). A lookup
// table sized at start: routing an event is two loads.
#pragma once

#include <cstdint>
#include <vector>

#include "evlife/algo/event.h"

namespace evlife::engine {

class TileLayout {
 public:
  static constexpr int kMaxWorkers = 32;
  static constexpr std::uint8_t kNoOwner = 0xFF;

  /// Throws std::invalid_argument on a bad geometry (names the field).
  TileLayout(SensorSize sensor, int workers, int tiles_x, int tiles_y, int margin_px);

  /// Owner of an event, or kNoOwner for coordinates outside the sensor or a
  /// polarity other than +1/-1 (the router hands those to worker 0, which
  /// the estimator rejects and counts as noise, so nothing vanishes).
  std::uint8_t owner(const Event& e) const noexcept {
    const long long i = index(e);
    return i < 0 ? kNoOwner : owner_[static_cast<std::size_t>(i)];
  }
  /// Bit w set: worker w must process the event (owner's bit included).
  std::uint32_t feed_mask(const Event& e) const noexcept {
    const long long i = index(e);
    return i < 0 ? 0u : feed_[static_cast<std::size_t>(i)];
  }

  int workers() const noexcept { return workers_; }
  int tiles_x() const noexcept { return tiles_x_; }
  int tiles_y() const noexcept { return tiles_y_; }
  int margin_px() const noexcept { return margin_px_; }
  SensorSize sensor() const noexcept { return sensor_; }

  /// Worker that owns tile (polarity_index 0 = ON, 1 = OFF; tile column, row).
  int tile_owner(int polarity_index, int tile_col, int tile_row) const noexcept;

 private:
  long long index(const Event& e) const noexcept {
    if (e.x >= sensor_.width || e.y >= sensor_.height || (e.p != 1 && e.p != -1)) return -1;
    const long long pi = e.p > 0 ? 0 : 1;
    return (pi * sensor_.height + e.y) * sensor_.width + e.x;
  }

  SensorSize sensor_;
  int workers_;
  int tiles_x_;
  int tiles_y_;
  int margin_px_;
  std::vector<std::uint8_t> owner_;  // [polarity][y][x]
  std::vector<std::uint32_t> feed_;  // [polarity][y][x]
};

}  // namespace evlife::engine
