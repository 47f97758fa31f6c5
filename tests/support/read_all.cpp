#include "read_all.h"

namespace evlife::test {

ReadAll read_all(const std::string& path, const io::ReaderOptions& options, std::size_t batch) {
  ReadAll r;
  const auto reader = io::open_event_reader(path, options);
  r.format = reader->format_name();
  r.sensor = reader->sensor_size();
  r.streams = reader->streams();
  std::vector<Event> buffer(batch);
  try {
    while (const std::size_t n = reader->read(buffer))
      r.events.insert(r.events.end(), buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(n));
  } catch (const io::ReadError& e) {
    r.error = e;
  }
  r.skipped = reader->skipped_record_count();
  r.triggers = reader->trigger_count();
  r.kinds = reader->skipped_record_kinds();
  return r;
}

std::string open_error(const std::string& path, const io::ReaderOptions& options) {
  try {
    (void)io::open_event_reader(path, options);
  } catch (const io::ReadError& e) {
    return e.what();
  }
  return "opened without error";
}

}  // namespace evlife::test
