// Prophesee RAW, EVT 2.1 (GenX320, also IMX636): `%` header, then 64-bit
// words whose top 4 bits give the type: EVT_NEG 0 / EVT_POS 1 (t low 6 bits
// at 54-59, x of a 32-pixel group at 43-53, y at 32-42, bit n of 0-31: an
// event at x + n), EVT_TIME_HIGH 8 (bits 32-59 = t >> 6), EXT_TRIGGER 10
// (skipped, counted), OTHERS 14 (skipped, counted).
//
// Byte order (Prophesee's EVT 2.1 page): GenX320 stores each word as one
// little-endian 64-bit value; IMX636 as two little-endian 32-bit halves,
// the upper half first. The reader tells them apart from the words after the
// header (Evt21Reader::Layout), not from the camera's name.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "chunked_file.h"
#include "prophesee_time_high.h"
#include "evlife/io/event_reader.h"

namespace evlife::io {

class Evt21Reader final : public EventReader {
 public:
  /// Throws ReadError if the file cannot be opened or is not EVT 2.1.
  explicit Evt21Reader(const std::string& path);

  std::size_t read(std::span<Event> out) override;
  std::optional<SensorSize> sensor_size() const override { return sensor_; }
  std::string_view format_name() const override { return "evt21"; }
  std::string clock_wrap_note() const override { return PropheseeTimeHigh::wrap_note(); }
  const std::string& path() const override { return file_.path(); }
  std::uint64_t skipped_record_count() const override {
    return trigger_count_ + other_count_ + before_time_base_count_;
  }
  std::vector<SkippedKindCount> skipped_record_kinds() const override {
    return prophesee_skipped_kinds(trigger_count_, other_count_, before_time_base_count_);
  }
  std::uint64_t bytes_consumed() const override {
    return static_cast<std::uint64_t>(file_.offset());
  }
  std::uint64_t trigger_count() const override { return trigger_count_; }

  /// How the 8 bytes of a word are ordered in the file.
  enum class Layout { whole_word, upper_half_first };
  /// The layout under which `words` (8-byte words, the file's first ones)
  /// look like EVT 2.1: fewer reserved types, TIME_HIGH words with a zero
  /// lower half, event words with a nonzero mask and a nonzero upper half.
  /// Ties: whole_word.
  static Layout detect_layout(std::span<const std::uint8_t> words) noexcept;

 private:
  ChunkedFile file_;
  std::optional<SensorSize> sensor_;
  Layout layout_ = Layout::whole_word;
  std::uint32_t max_x_ = 0x7FF;  // inclusive bounds: the sensor, else the field width
  std::uint32_t max_y_ = 0x7FF;
  PropheseeTimeHigh time_high_;
  // The last event word and the pixels of its mask not yet emitted (the
  // caller's buffer was full). No word is read while any are left, so
  // time_high_ is still the word's.
  std::uint64_t pending_word_ = 0;
  std::uint32_t pending_mask_ = 0;
  std::uint64_t trigger_count_ = 0;
  std::uint64_t other_count_ = 0;
  std::uint64_t before_time_base_count_ = 0;  // events before the first TIME_HIGH
  std::int64_t event_count_ = 0;
  std::optional<ReadError> error_;
};

}  // namespace evlife::io
