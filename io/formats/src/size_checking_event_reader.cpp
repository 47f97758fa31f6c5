#include "size_checking_event_reader.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <string>
#include <utility>

namespace evlife::io::detail {

SizeCheckingEventReader::SizeCheckingEventReader(std::unique_ptr<EventReader> inner, int fd,
                                                 std::int64_t size_at_open)
    : WrappingEventReader(std::move(inner)), fd_(fd), size_at_open_(size_at_open) {}

SizeCheckingEventReader::~SizeCheckingEventReader() { ::close(fd_); }

std::unique_ptr<EventReader> SizeCheckingEventReader::wrap(std::unique_ptr<EventReader> inner,
                                                           const std::string& path) {
  // O_NONBLOCK: never waits on a FIFO (not wrapped: only regular files are).
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) return inner;
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || st.st_size == 0) {
    ::close(fd);
    return inner;
  }
  return std::make_unique<SizeCheckingEventReader>(std::move(inner), fd, static_cast<std::int64_t>(st.st_size));
}

std::int64_t SizeCheckingEventReader::skip_events_before(std::int64_t t_us) {
  const std::int64_t passed = inner_->skip_events_before(t_us);
  delivered_ += passed;
  return passed;
}

std::size_t SizeCheckingEventReader::read(std::span<Event> out) {
  const std::size_t n = inner_->read(out);
  delivered_ += static_cast<std::int64_t>(n);
  if (n > 0 || out.empty()) return n;
  struct stat st {};
  if (::fstat(fd_, &st) == 0 && st.st_size < size_at_open_) {
    throw ReadError(path(), static_cast<std::int64_t>(st.st_size), delivered_,
                    "the file is now " + std::to_string(st.st_size) + " bytes long, " + std::to_string(size_at_open_) +
                        " when it was opened: cut while being read; the events before were read");
  }
  return 0;
}

}  // namespace evlife::io::detail
