#include "evlife/io/sensor_size_from_data.h"

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "evlife/io/event_reader.h"

namespace evlife::io {

SensorSize sensor_size_from_data(const std::string& path, const ReaderOptions& input,
                                 const std::atomic<bool>* stop) {
  if (stop == nullptr) return sensor_size_from_data_until(path, input, {});
  return sensor_size_from_data_until(path, input, [stop] { return stop->load(std::memory_order_relaxed); });
}

SensorSize sensor_size_from_data_until(const std::string& path, const ReaderOptions& input,
                                       const std::function<bool()>& stop_requested) {
  // Time order is not checked here: this pass only looks at coordinates;
  // the processing pass reports ordering faults with their index.
  ReaderOptions options = input;
  // The sensor holds every event of the file, cropped or not.
  options.from_us.reset();
  options.to_us.reset();
  options.polarity = PolarityFilter::both;
  options.require_time_order = false;
  options.sensor = SensorSize{65536, 65536};  // the Event coordinate range: never fails
  const std::unique_ptr<EventReader> reader = open_event_reader(path, options);
  std::vector<Event> buffer(1 << 16);
  int max_x = -1, max_y = -1;
  std::int64_t scanned = 0;
  try {
    while (const std::size_t n = reader->read(buffer)) {
      for (std::size_t i = 0; i < n; ++i) {
        max_x = std::max<int>(max_x, buffer[i].x);
        max_y = std::max<int>(max_y, buffer[i].y);
      }
      if (max_x >= kMaxSensorSide || max_y >= kMaxSensorSide) {
        // No camera is this large: a corrupt record, most likely. Named here
        // (the estimator's own check said only "sensor.width: 5001 must be in
        // [1, 4096]", with no event to look at).
        std::size_t i = 0;
        while (buffer[i].x < kMaxSensorSide && buffer[i].y < kMaxSensorSide) ++i;
        throw ReadError(path, -1, scanned + static_cast<std::int64_t>(i),
                        "event at (x " + std::to_string(buffer[i].x) + ", y " + std::to_string(buffer[i].y) +
                            ") is beyond any camera (at most " + std::to_string(kMaxSensorSide) +
                            " px a side) and the file states no sensor: a corrupt record? (With --sensor WxH "
                            "the events before it are processed, then it is reported)");
      }
      scanned += static_cast<std::int64_t>(n);
      if (stop_requested && stop_requested()) {
        return SensorSize{std::max(max_x, 0) + 1, std::max(max_y, 0) + 1};
      }
    }
  } catch (const ReadError&) {
    // A fault after some events: the sensor of the events before it; the
    // processing pass delivers those and then reports the fault (no loss).
    if (max_x < 0 || max_x >= kMaxSensorSide || max_y >= kMaxSensorSide) throw;
  }
  if (max_x < 0) throw ReadError(path, -1, -1, "no events: cannot infer the sensor size");
  return SensorSize{max_x + 1, max_y + 1};
}

std::string_view to_string(SensorSizeSource source) {
  switch (source) {
    case SensorSizeSource::format: return "stated by the file format";
    case SensorSizeSource::user: return "given by the user";
    case SensorSizeSource::data: return "inferred from the data (max x + 1, max y + 1)";
  }
  return "?";
}

std::optional<SensorSize> stated_sensor_size(const EventReader& probe, std::optional<SensorSize> user) {
  if (user && !probe.sensor_size_note().empty()) return std::nullopt;  // a guess yields to the user
  return probe.sensor_size();
}

ResolvedSensorSize resolve_sensor_size(const std::string& path, std::optional<SensorSize> user,
                                       const ReaderOptions& input, const std::atomic<bool>* stop) {
  if (const auto stated = stated_sensor_size(*open_unchecked_event_reader(path, input), user))
    return {*stated, SensorSizeSource::format};
  if (user) return {*user, SensorSizeSource::user};
  return {sensor_size_from_data(path, input, stop), SensorSizeSource::data};
}

}  // namespace evlife::io
