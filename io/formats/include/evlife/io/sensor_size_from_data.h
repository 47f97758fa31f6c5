// Sensor size when neither the format nor the user states it: one pass over
// the file, the smallest sensor holding every event.
#pragma once

#include <atomic>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "evlife/algo/event.h"
#include "evlife/io/event_reader.h"

namespace evlife::io {

/// Reads `path` once (constant memory) and returns {max x + 1, max y + 1}:
/// the one rule for a sensor size taken from the data (`process`, `render`,
/// `run`, the engine's replay). A read fault after some events ends the scan
/// there (the processing pass reports it after delivering those events).
/// Throws ReadError when the file cannot be read or holds no event.
/// `input`: the caller's input selection (topic...); its sensor and
/// time-order settings are replaced. `stop` (a command's stop flag) ends the
/// scan early: the size of the events scanned so far (1 x 1 before any), for
/// an output that will hold no event.
SensorSize sensor_size_from_data(const std::string& path, const ReaderOptions& input = {},
                                 const std::atomic<bool>* stop = nullptr);
/// The same, asking `stop_requested` between blocks of events (Python's
/// Ctrl-C check, which needs its interpreter).
SensorSize sensor_size_from_data_until(const std::string& path, const ReaderOptions& input,
                                       const std::function<bool()>& stop_requested);

/// Where a resolved sensor size came from (for the user's summary).
enum class SensorSizeSource { format, user, data };
std::string_view to_string(SensorSizeSource source);

/// The sensor size `probe`'s file states, unless the reader only guessed it
/// (EventReader::sensor_size_note(): v2e's AEDAT 2.0) and the user gave one:
/// the first step of every command's sensor rule.
std::optional<SensorSize> stated_sensor_size(const EventReader& probe, std::optional<SensorSize> user);

struct ResolvedSensorSize {
  SensorSize size;
  SensorSizeSource source = SensorSizeSource::format;
};

/// The format's sensor where it states one, else `user` (--sensor), else
/// sensor_size_from_data(path, input, stop). (Augmented files: io::sensor_size_of_augmented.)
ResolvedSensorSize resolve_sensor_size(const std::string& path,
                                       std::optional<SensorSize> user,
                                       const ReaderOptions& input = {},
                                       const std::atomic<bool>* stop = nullptr);

}  // namespace evlife::io
