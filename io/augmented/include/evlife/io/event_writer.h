// Writer of plain events, for commands that produce or convert recordings.
#pragma once

#include <memory>
#include <optional>
#include <span>
#include <string>

#include "evlife/algo/event.h"
#include "evlife/io/write_error.h"

namespace evlife::io {

class EventWriter {
 public:
  /// Never throws (see AugmentedEventWriter).
  virtual ~EventWriter() = default;
  /// Appends (buffered). Throws WriteError naming the file.
  virtual void write(std::span<const Event> events) = 0;
  /// Flushes and closes; throws WriteError on failure. Idempotent.
  virtual void close() = 0;
  virtual const std::string& path() const = 0;
};

/// RPG event-camera text format, one event per line `t x y p`: t in seconds
/// with exactly 6 decimals (exact from integer µs, no floating point), x y
/// 0-based (top-left origin), p 1 (ON) or 0 (OFF). Reads back with
/// open_event_reader bit for bit. Throws WriteError if the file cannot be created.
std::unique_ptr<EventWriter> open_rpg_text_writer(const std::string& path);

/// By extension: `.txt` → RPG text, `.h5` / `.hdf5` → HDF5 x,y,t,p with the
/// sensor as its width / height attributes (when given; the text format has
/// no place for it). Throws WriteError for others.
std::unique_ptr<EventWriter> open_event_writer(const std::string& path,
                                               std::optional<SensorSize> sensor = std::nullopt);

}  // namespace evlife::io
