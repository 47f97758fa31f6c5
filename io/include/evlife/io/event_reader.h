// Streaming event readers: constant memory, any file size. Formats are
// sniffed from the header (or the extension where the format has none).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>

#include "evlife/algo/event.h"

namespace evlife::io {

/// A read failure: names the file and where (byte offset and/or index of
/// the event at fault; -1 when unknown).
class ReadError : public std::runtime_error {
 public:
  ReadError(const std::string& path, std::int64_t byte_offset, std::int64_t event_index,
            const std::string& what);
  const std::string& path() const noexcept { return path_; }
  std::int64_t byte_offset() const noexcept { return byte_offset_; }
  std::int64_t event_index() const noexcept { return event_index_; }

 private:
  std::string path_;
  std::int64_t byte_offset_;
  std::int64_t event_index_;
};

class EventReader {
 public:
  virtual ~EventReader() = default;

  /// Fills `out` with up to out.size() events, in file order, and returns how
  /// many; 0 means end of stream. On corrupt or truncated data the events
  /// decoded before the fault are returned first; the call after throws
  /// ReadError (so nothing good is lost).
  virtual std::size_t read(std::span<Event> out) = 0;

  /// Sensor size when the format states it.
  virtual std::optional<SensorSize> sensor_size() const = 0;

  /// Short format name, e.g. "mat", "rpg-text", "aedat2".
  virtual std::string_view format_name() const = 0;

  virtual const std::string& path() const = 0;
};

/// Opens `path`, sniffing its format. Throws ReadError for a missing or
/// unreadable file or an unknown format (the message lists the known ones).
std::unique_ptr<EventReader> open_event_reader(const std::string& path);

}  // namespace evlife::io
