// Shared body of the reader fuzz targets (fuzz_<format>.cpp): the input is
// read through evlife::io::open_event_reader until the end or a ReadError.
// Findings: a crash or sanitizer report, an exception other than ReadError,
// or a broken reader contract (an event outside the stated sensor, a bad
// polarity, time going backwards, events after the end or after an error;
// with `also_skip`, a skip_events_before() that disagrees with the whole read).
#pragma once

#include <array>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "evlife/io/event_reader.h"
#include "fuzz_input_file.h"

namespace evlife::fuzz {

inline void contract_violation(const char* what) {
  std::fprintf(stderr, "evlife fuzz: reader contract broken: %s\n", what);
  std::abort();
}

/// After a whole read of `total` events from first_t_us to last_t_us that
/// ended cleanly: a second reader skips the events before the middle time
/// (for readers that search, e.g. HDF5's binary search on t, which corrupt
/// files must not crash either); what it passes and what it reads then must
/// add up to the whole read, in time order; --from that time (ReaderOptions)
/// must read the same events.
inline void fuzz_skip(const std::string& path, std::size_t total, std::int64_t first_t_us,
                      std::int64_t last_t_us) {
  const std::int64_t middle = first_t_us + (last_t_us - first_t_us) / 2;
  std::unique_ptr<io::EventReader> reader = io::open_event_reader(path);  // opened before
  const std::int64_t skipped = reader->skip_events_before(middle);
  if (skipped < 0 || static_cast<std::size_t>(skipped) > total) contract_violation("skipped more events than the file holds");
  std::array<Event, 251> batch{};
  std::size_t rest = 0;
  try {
    while (const std::size_t n = reader->read(batch)) {
      if (skipped > 0 && batch[0].t_us < middle && rest == 0) contract_violation("skipped to an event before the time asked");
      rest += n;
    }
  } catch (const io::ReadError&) {
    contract_violation("a skip made a clean file fail");
  }
  if (static_cast<std::size_t>(skipped) + rest != total) contract_violation("skipped + read != the whole read");
  // --from the same time (it counts from the first event; a reader that can
  // seek starts there by the same search): the same events.
  io::ReaderOptions from_middle;
  from_middle.from_us = middle - first_t_us;
  std::unique_ptr<io::EventReader> cropped = io::open_event_reader(path, from_middle);
  std::size_t from_count = 0;
  try {
    while (const std::size_t n = cropped->read(batch)) {
      if (batch[0].t_us < middle) contract_violation("--from delivered an event before its time");
      from_count += n;
    }
  } catch (const io::ReadError&) {
    contract_violation("--from made a clean file fail");
  }
  if (from_count != rest) contract_violation("--from read other events than a skip to its time");
}

/// Reads the whole input; `max_events` bounds the work per input (a few KB of
/// compressed data can legitimately expand to millions of events).
inline int fuzz_event_reader(const std::uint8_t* data, std::size_t size, const char* extension,
                             std::size_t max_events = std::size_t{1} << 20, bool also_skip = false) {
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
  std::int64_t first_t_us = INT64_MIN;
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
        if (total == 0 && i == 0) first_t_us = e.t_us;
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
    if (also_skip && total > 0) fuzz_skip(path, total, first_t_us, last_t_us);
  }
  return 0;
}

}  // namespace evlife::fuzz
