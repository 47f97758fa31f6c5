// Private: wraps the decoder of a regular file and, where the decoder ends
// its stream, checks that the file is not shorter than when it was opened: a
// recording cut while being read (a copy still in progress, a disk filling
// up) ends in a ReadError after every event before the cut, never in a quiet
// end of stream that hides the lost tail. A file that grew is fine. The size
// is the opened file's (a descriptor of its own), not the path's: a file
// renamed over the path meanwhile is not the one read.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>

#include "wrapping_event_reader.h"

namespace evlife::io::detail {

class SizeCheckingEventReader final : public WrappingEventReader {
 public:
  /// `inner` reads the regular file inner->path(); `fd` is a descriptor of
  /// that file (owned: closed by the destructor), `size_at_open` its size.
  SizeCheckingEventReader(std::unique_ptr<EventReader> inner, int fd, std::int64_t size_at_open);
  ~SizeCheckingEventReader() override;
  SizeCheckingEventReader(const SizeCheckingEventReader&) = delete;
  SizeCheckingEventReader& operator=(const SizeCheckingEventReader&) = delete;

  /// `inner` wrapped when `path` is a regular file that opens, else `inner` itself.
  static std::unique_ptr<EventReader> wrap(std::unique_ptr<EventReader> inner, const std::string& path);

  std::size_t read(std::span<Event> out) override;
  std::int64_t byte_offset_of_event(std::int64_t event_index) const override {
    return inner_->byte_offset_of_event(event_index);
  }
  std::int64_t skip_events_before(std::int64_t t_us) override;
  std::optional<std::int64_t> first_event_time_us() const override { return inner_->first_event_time_us(); }

 private:
  int fd_;
  std::int64_t size_at_open_;
  std::int64_t delivered_ = 0;  // events returned or skipped so far: the index of the next
};

}  // namespace evlife::io::detail
