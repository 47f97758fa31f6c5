// Per-pixel burst and interval statistics of an event stream (see pixel_statistics.h).
#include "evlife/render/pixel_statistics.h"

#include <algorithm>
#include <stdexcept>

namespace evlife::render {
namespace {

double quantile(std::vector<std::int64_t>& v, double q) {
  if (v.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return static_cast<double>(v[k]);
}

}  // namespace

PixelStatisticsAccumulator::PixelStatisticsAccumulator(SensorSize sensor, std::int64_t burst_gap_us)
    : sensor_(sensor), gap_us_(burst_gap_us), state_(static_cast<std::size_t>(sensor.pixel_count()) * 2) {
  if (burst_gap_us <= 0) throw std::invalid_argument("pixel statistics: burst gap must be > 0");
}

void PixelStatisticsAccumulator::close_burst(PixelState& s) {
  if (s.burst_size == 0) return;
  ++stats_.bursts;
  ++stats_.bursts_by_size[std::min<std::size_t>(s.burst_size, 4) - 1];
  s.burst_size = 0;
}

void PixelStatisticsAccumulator::add(std::span<const Event> events) {
  for (const Event& e : events) {
    if (!sensor_.contains(e.x, e.y)) continue;
    PixelState& s = state_[(static_cast<std::size_t>(e.y) * static_cast<std::size_t>(sensor_.width) + e.x) * 2 + (e.p > 0 ? 1 : 0)];
    ++stats_.events;
    if (s.last_t_us >= 0) {
      const std::int64_t gap = e.t_us - s.last_t_us;
      intervals_us_.push_back(gap);
      if (gap >= gap_us_) close_burst(s);
    }
    ++s.burst_size;
    s.last_t_us = e.t_us;
  }
}

PixelStatistics PixelStatisticsAccumulator::finish() {
  for (PixelState& s : state_) close_burst(s);
  stats_.intervals = intervals_us_.size();
  stats_.interval_p10_us = quantile(intervals_us_, 0.10);
  stats_.interval_median_us = quantile(intervals_us_, 0.50);
  stats_.interval_p90_us = quantile(intervals_us_, 0.90);
  return stats_;
}

PixelStatistics pixel_statistics(std::span<const Event> events, SensorSize sensor, std::int64_t burst_gap_us) {
  PixelStatisticsAccumulator acc(sensor, burst_gap_us);
  acc.add(events);
  return acc.finish();
}

}  // namespace evlife::render
