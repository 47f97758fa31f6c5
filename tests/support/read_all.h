// Everything a reader opened as every command opens it (io::open_event_reader)
// delivers, read in batches of a chosen size, and the error that ended it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "evlife/algo/event.h"
#include "evlife/io/event_reader.h"

namespace evlife::test {

struct ReadAll {
  std::string format;
  std::optional<SensorSize> sensor;
  std::vector<Event> events;
  std::uint64_t skipped = 0;  ///< skipped_record_count() after the read
  std::uint64_t triggers = 0;
  std::vector<io::SkippedKindCount> kinds;
  std::vector<io::ContainerStream> streams;
  std::optional<io::ReadError> error;  ///< the read's fault; an open error is thrown
};

/// Reads `path` to its end (or its fault) in batches of `batch` events; a
/// batch size that divides nothing exercises the readers' carry-over.
ReadAll read_all(const std::string& path, const io::ReaderOptions& options = {}, std::size_t batch = 1000);

/// What the ReadError that opening `path` throws says ("opened without error"
/// when it opens).
std::string open_error(const std::string& path, const io::ReaderOptions& options = {});

}  // namespace evlife::test
