#include "evlife/render/fixed_window_map.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace evlife::render {

FixedWindowMap::FixedWindowMap(SensorSize sensor) : sensor_(sensor) {
  if (sensor.width < 1 || sensor.height < 1 || sensor.width > 16384 || sensor.height > 16384) {
    throw std::invalid_argument("FixedWindowMap: sensor size " + std::to_string(sensor.width) +
                                "x" + std::to_string(sensor.height) +
                                " out of range 1..16384 each way");
  }
  last_t_us_.assign(static_cast<std::size_t>(sensor.pixel_count()), kNever);
  polarity_.assign(static_cast<std::size_t>(sensor.pixel_count()), 0);
}

void FixedWindowMap::reset() noexcept {
  std::fill(last_t_us_.begin(), last_t_us_.end(), kNever);
  std::fill(polarity_.begin(), polarity_.end(), std::int8_t{0});
  out_of_sensor_ = 0;
}

std::size_t FixedWindowMap::count_active(std::int64_t t_us, std::int64_t window_us) const noexcept {
  std::size_t n = 0;
  for (std::size_t i = 0; i < last_t_us_.size(); ++i) n += is_active(i, t_us, window_us) ? 1u : 0u;
  return n;
}

}  // namespace evlife::render
