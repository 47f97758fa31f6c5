// Shared body of the reader fuzz targets (fuzz_<format>.cpp): the input is
// read through evlife::io::open_event_reader until the end or a ReadError.
// Findings: a crash or sanitizer report, an exception other than ReadError,
// or a broken reader contract (an event outside the stated sensor, a bad
// polarity, time going backwards, events after the end or after an error).
#pragma once

#include <array>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "evlife/io/event_reader.h"
#include "fuzz_input_file.h"

namespace evlife::fuzz {

inline void contract_violation(const char* what) {
  std::fprintf(stderr, "evlife fuzz: reader contract broken: %s\n", what);
  std::abort();
}

/// Reads the whole input; `max_events` bounds the work per input (a few KB of
/// compressed data can legitimately expand to millions of events).
inline int fuzz_event_reader(const std::uint8_t* data, std::size_t size, const char* extension,
                             std::size_t max_events = std::size_t{1} << 20) {
  const std::string& path = write_input_file(data, size, extension);
  static bool registered = (remove_input_file_at_exit(path), true);
  (void)registered;
  std::unique_ptr<io::EventReader> reader;
  try {
    reader = io::open_event_reader(path);
  } catch (const io::ReadError&) {
    return 0;  // refused at open, with a message: fine
  }
  const auto sensor = reader->sensor_size();
  // An odd buffer size exercises reads that end mid-chunk.
  std::array<Event, 251> batch{};
  std::size_t total = 0;
  std::int64_t last_t_us = INT64_MIN;
  bool ended = false;
  try {
    while (total < max_events) {
      const std::size_t n = reader->read(batch);
      if (n > batch.size()) contract_violation("read() returned more than the buffer holds");
      if (n == 0) {
        ended = true;
        break;
      }
      for (std::size_t i = 0; i < n; ++i) {
        const Event& e = batch[i];
        if (e.p != 1 && e.p != -1) contract_violation("polarity not +1/-1");
        if (e.t_us < last_t_us) contract_violation("timestamps going backwards");
        if (sensor && (e.x >= sensor->width || e.y >= sensor->height))
          contract_violation("event outside the sensor the reader states");
        last_t_us = e.t_us;
      }
      total += n;
      (void)reader->bytes_consumed();
      (void)reader->byte_offset_of_event(static_cast<std::int64_t>(total - 1));
    }
  } catch (const io::ReadError& e) {
    if (e.what()[0] == '\0') contract_violation("ReadError without a message");
    return 0;
  }
  if (ended) {  // the end is final
    try {
      if (reader->read(batch) != 0) contract_violation("events after the end of the stream");
    } catch (const io::ReadError&) {
      contract_violation("ReadError after the end of the stream");
    }
  }
  return 0;
}

}  // namespace evlife::fuzz
