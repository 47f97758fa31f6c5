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
    if (!valid(e)) return kNoOwner;
    return tile_worker_[tile_index(e.p > 0 ? 0 : 1, col_of_x_[e.x], row_of_y_[e.y])];
  }

  /// Bit w set: worker w must process the event (owner's bit included).
  std::uint32_t feed_mask(const Event& e) const noexcept {
    if (!valid(e)) return 0u;
    const int pi = e.p > 0 ? 0 : 1;
    const Span cols = feed_cols_[e.x], rows = feed_rows_[e.y];
    std::uint32_t mask = 0;
    for (int r = rows.first; r <= rows.last; ++r)
      for (int c = cols.first; c <= cols.last; ++c) mask |= 1u << tile_worker_[tile_index(pi, c, r)];
    return mask;
  }

  /// True when every event is fed to its owner only (one tile per polarity,
  /// or no margin): routing then needs owner() alone.
  bool owner_only() const noexcept { return owner_only_; }
  int workers() const noexcept { return workers_; }
  int tiles_x() const noexcept { return tiles_x_; }
  int tiles_y() const noexcept { return tiles_y_; }
  int margin_px() const noexcept { return margin_px_; }
  SensorSize sensor() const noexcept { return sensor_; }

  /// Worker that owns tile (polarity_index 0 = ON, 1 = OFF; tile column, row).
  int tile_owner(int polarity_index, int tile_col, int tile_row) const noexcept {
    return tile_worker_[tile_index(polarity_index, tile_col, tile_row)];
  }

 private:
  // Tiles whose margin-grown extent covers a column (row): a contiguous range.
  struct Span {
    std::uint16_t first;
    std::uint16_t last;
  };
  bool valid(const Event& e) const noexcept {
    return e.x < sensor_.width && e.y < sensor_.height && (e.p == 1 || e.p == -1);
  }
  std::size_t tile_index(int pi, int col, int row) const noexcept {
    return static_cast<std::size_t>(pi * tiles_y_ + row) * static_cast<std::size_t>(tiles_x_) +
           static_cast<std::size_t>(col);
  }

  SensorSize sensor_;
  int workers_;
  int tiles_x_;
  int tiles_y_;
  int margin_px_;
  // Small tables (sensor width + height + tiles): stay in cache, unlike a
  // per-pixel map of a 1280x720 sensor.
  std::vector<std::uint16_t> col_of_x_;
  std::vector<std::uint16_t> row_of_y_;
  std::vector<Span> feed_cols_;
  std::vector<Span> feed_rows_;
  std::vector<std::uint8_t> tile_worker_;  // [polarity][row][col]
  bool owner_only_ = false;
};

}  // namespace evlife::engine
