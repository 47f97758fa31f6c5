// What the pixels of an event stream do, per pixel and polarity: how many
// events one edge gives (bursts), the intervals between a pixel's events, the
// share of burst followers. Measured the same way on real recordings and on
// the synthetic scenes, to check the DVS pixel model (io/synthetic_scene.h)
// against real sensors.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "evlife/algo/event.h"

namespace evlife::render {

struct PixelStatistics {
  std::uint64_t events = 0;
  std::uint64_t bursts = 0;
  /// Bursts of 1, 2, 3 and 4+ events.
  std::array<std::uint64_t, 4> bursts_by_size{};
  /// Intervals between consecutive same-polarity events at a pixel (us).
  std::uint64_t intervals = 0;
  double interval_p10_us = 0.0;
  double interval_median_us = 0.0;
  double interval_p90_us = 0.0;

  double mean_burst_size() const noexcept {
    return bursts == 0 ? 0.0 : static_cast<double>(events) / static_cast<double>(bursts);
  }
  /// Share of events that are not the first of their burst.
  double follower_share() const noexcept {
    return events == 0 ? 0.0 : static_cast<double>(events - bursts) / static_cast<double>(events);
  }
  double burst_share(std::size_t size_class) const noexcept {
    return bursts == 0 ? 0.0 : static_cast<double>(bursts_by_size[size_class]) / static_cast<double>(bursts);
  }
};

/// Streaming accumulator: add events in time order, then finish().
/// A burst = consecutive events of one pixel and polarity less than
/// burst_gap_us apart.
class PixelStatisticsAccumulator {
 public:
  explicit PixelStatisticsAccumulator(SensorSize sensor, std::int64_t burst_gap_us = 5000);

  /// Events outside the sensor are ignored.
  void add(std::span<const Event> events);
  PixelStatistics finish();

 private:
  struct PixelState {
    std::int64_t last_t_us = -1;  // -1: no event yet
    std::uint32_t burst_size = 0;
  };
  void close_burst(PixelState& s);

  SensorSize sensor_;
  std::int64_t gap_us_;
  std::vector<PixelState> state_;  // (y * width + x) * 2 + (p > 0)
  std::vector<std::int64_t> intervals_us_;
  PixelStatistics stats_;
};

/// All at once.
PixelStatistics pixel_statistics(std::span<const Event> events, SensorSize sensor,
                                 std::int64_t burst_gap_us = 5000);

}  // namespace evlife::render
