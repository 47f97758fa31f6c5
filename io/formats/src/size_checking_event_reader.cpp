#include "size_checking_event_reader.h"

#include <filesystem>
#include <string>
#include <system_error>
#include <utility>

namespace evlife::io::detail {

SizeCheckingEventReader::SizeCheckingEventReader(std::unique_ptr<EventReader> inner, std::uintmax_t size_at_open)
    : WrappingEventReader(std::move(inner)), size_at_open_(size_at_open) {}

std::int64_t SizeCheckingEventReader::skip_events_before(std::int64_t t_us) {
  const std::int64_t passed = inner_->skip_events_before(t_us);
  delivered_ += passed;
  return passed;
}

std::size_t SizeCheckingEventReader::read(std::span<Event> out) {
  const std::size_t n = inner_->read(out);
  delivered_ += static_cast<std::int64_t>(n);
  if (n > 0 || out.empty()) return n;
  std::error_code ec;
  const std::uintmax_t now = std::filesystem::file_size(path(), ec);
  if (!ec && now < size_at_open_) {
    throw ReadError(path(), static_cast<std::int64_t>(now), delivered_,
                    "the file is now " + std::to_string(now) + " bytes long, " + std::to_string(size_at_open_) +
                        " when it was opened: cut while being read; the events before were read");
  }
  return 0;
}

}  // namespace evlife::io::detail
