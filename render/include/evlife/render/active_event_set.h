// The active-event map moved to algo/ (evlife/algo/active_event_map.h, no
// OpenCV): this header keeps the old render:: names compiling.
#pragma once

#include <cstdint>
#include <string>

#include "evlife/algo/active_event_map.h"

namespace evlife::render {
using ActiveEventSet = evlife::ActiveEventMap;
using ActiveEventSetStats = evlife::ActiveEventMapStats;

/// The events a map left out of every frame: outside the sensor, older than
/// their pixel's event, a time beyond +-2^62 us.
inline std::uint64_t ignored_events(const ActiveEventSetStats& s) noexcept {
  return s.out_of_sensor + s.late + s.time_out_of_range;
}
/// "N outside the sensor, N older than their pixel's event, N time beyond
/// +-2^62 us": how `render` and `eval` say so.
std::string ignored_events_text(const ActiveEventSetStats& s);
}  // namespace evlife::render
