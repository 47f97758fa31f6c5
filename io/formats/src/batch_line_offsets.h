// Where each event of a text reader's last batch began in the file, so that
// the checked reader's "outside the sensor" / "goes backwards" faults name the
// line's byte offset (EventReader::byte_offset_of_event). One slot per event of
// the batch, sized once per batch size.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "evlife/io/event_reader.h"

namespace evlife::io::detail {

class BatchLineOffsets {
 public:
  /// A batch of up to `capacity` events starts at event `first_index`.
  void begin(std::uint64_t first_index, std::size_t capacity) {
    first_index_ = first_index;
    offsets_.resize(capacity);  // no-op after the first batch of this size
  }
  void set(std::size_t slot, std::uint64_t line_offset) noexcept { offsets_[slot] = line_offset; }

  /// The offset of event `event_index`: in the last batch (events up to
  /// next_index), or the pending fault's at next_index; else -1.
  std::int64_t of(std::int64_t event_index, std::uint64_t next_index,
                  const std::optional<ReadError>& pending) const noexcept {
    const std::int64_t i = event_index - static_cast<std::int64_t>(first_index_);
    if (i >= 0 && i < static_cast<std::int64_t>(next_index - first_index_))
      return static_cast<std::int64_t>(offsets_[static_cast<std::size_t>(i)]);
    if (event_index == static_cast<std::int64_t>(next_index) && pending) return pending->byte_offset();
    return -1;
  }

 private:
  std::uint64_t first_index_ = 0;
  std::vector<std::uint64_t> offsets_;
};

}  // namespace evlife::io::detail
