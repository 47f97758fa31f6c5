// Prophesee RAW, EVT 2.1 (GenX320, also IMX636): `%` header, then 64-bit
// words whose top 4 bits give the type: EVT_NEG 0 / EVT_POS 1 (t low 6 bits
// at 54-59, x of a 32-pixel group at 43-53, y at 32-42, bit n of 0-31: an
// event at x + n), EVT_TIME_HIGH 8 (bits 32-59 = t >> 6), EXT_TRIGGER 10
// (skipped, counted), OTHERS 14 (skipped, counted). Two zero words in a row
// (no pixel set, twice: no encoder writes that) are an error at the first:
// a block of the file never written, as a power cut leaves it.
//
// Byte order (Prophesee's EVT 2.1 page): GenX320 stores each word as one
// little-endian 64-bit value; IMX636 as two little-endian 32-bit halves,
// the upper half first. The reader tells them apart from the words after the
// header (Evt21Reader::Layout), not from the camera's name.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "prophesee_word_reader.h"

namespace evlife::io {

class Evt21Reader final : public PropheseeWordReader {
 public:
  /// Throws ReadError if the file cannot be opened or is not EVT 2.1.
  explicit Evt21Reader(const std::string& path);

  std::size_t read(std::span<Event> out) override;
  std::string_view format_name() const override { return "evt21"; }

  /// How the 8 bytes of a word are ordered in the file.
  enum class Layout { whole_word, upper_half_first };
  /// The layout under which `words` (8-byte words, the file's first ones)
  /// look like EVT 2.1: fewer reserved types, TIME_HIGH words with a zero
  /// lower half, event words with a nonzero mask and a nonzero upper half.
  /// Ties: whole_word.
  static Layout detect_layout(std::span<const std::uint8_t> words) noexcept;

 private:
  Layout layout_ = Layout::whole_word;
  // The last event word and the pixels of its mask not yet emitted (the
  // caller's buffer was full). No word is read while any are left, so
  // time_high_ is still the word's.
  std::uint64_t pending_word_ = 0;
  std::uint32_t pending_mask_ = 0;
  bool previous_word_zero_ = false;  // the last word read was all zero (a second is an error)
};

}  // namespace evlife::io
