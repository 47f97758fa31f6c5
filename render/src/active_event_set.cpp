#include "evlife/render/active_event_set.h"

namespace evlife::render {

std::string ignored_events_text(const ActiveEventSetStats& s) {
  return std::to_string(s.out_of_sensor) + " outside the sensor, " + std::to_string(s.late) +
         " older than their pixel's event, " + std::to_string(s.time_out_of_range) + " time beyond +-2^62 us";
}

}  // namespace evlife::render
