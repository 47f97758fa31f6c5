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
  last_rel_.assign(static_cast<std::size_t>(sensor.pixel_count()), kNeverRel);
  polarity_.assign(static_cast<std::size_t>(sensor.pixel_count()), 0);
}

void FixedWindowMap::reset() noexcept {
  std::fill(last_rel_.begin(), last_rel_.end(), kNeverRel);
  epoch_us_ = 0;
  has_epoch_ = false;
  std::fill(polarity_.begin(), polarity_.end(), std::int8_t{0});
  out_of_sensor_ = 0;
  late_ = 0;
}

std::size_t FixedWindowMap::count_active(std::int64_t t_us, std::int64_t window_us) const noexcept {
  const RelWindow w = relative_window(t_us, window_us);
  std::size_t n = 0;
  for (std::size_t i = 0; i < last_rel_.size(); ++i) n += is_active_rel(i, w) ? 1u : 0u;
  return n;
}

// Moves the epoch so that t_us sits near the start of the int32 range;
// timestamps older than the longest exact window become "never".
void FixedWindowMap::rebase(std::int64_t t_us) noexcept {
  std::int64_t new_epoch = 0;
  if (__builtin_sub_overflow(t_us, kKeepUs, &new_epoch)) new_epoch = INT64_MIN;  // near the clock's start
  if (has_epoch_) {
    // The epoch only moves forward (times come in order), by up to 2^64 - 1 us.
    const std::uint64_t shift = since_epoch_us(new_epoch);
    for (std::int32_t& v : last_rel_) {
      if (v == kNeverRel) continue;
      const std::int64_t moved = shift > std::uint64_t{1} << 33 ? kNeverRel : static_cast<std::int64_t>(v) -
                                                                             static_cast<std::int64_t>(shift);
      v = moved <= kNeverRel ? kNeverRel : static_cast<std::int32_t>(moved);
    }
  }
  epoch_us_ = new_epoch;
  has_epoch_ = true;
}

}  // namespace evlife::render
