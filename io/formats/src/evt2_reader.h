// Prophesee RAW, EVT 2.0: `%` header, then little-endian 32-bit words whose
// top 4 bits give the type: CD_OFF 0 / CD_ON 1 (t low 6 bits at 22-27,
// x at 11-21, y at 0-10), EV_TIME_HIGH 8 (bits 0-27 = t >> 6), EXT_TRIGGER 10
// (skipped, counted), OTHERS 14 and the CONTINUED 15 words that go on from it
// (skipped, counted). A CONTINUED word after any other word continues nothing:
// an error (corrupt data: 0xFF bytes read as CONTINUED); so are two zero
// words in a row (two OFF events at (0, 0) in one microsecond: a block of the
// file never written, as a power cut leaves it), at the first of them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "prophesee_word_reader.h"

namespace evlife::io {

class Evt2Reader final : public PropheseeWordReader {
 public:
  /// Throws ReadError if the file cannot be opened or is not EVT 2.0.
  explicit Evt2Reader(const std::string& path) : PropheseeWordReader(path, "2.0") {}

  std::size_t read(std::span<Event> out) override;
  std::string_view format_name() const override { return "evt2"; }

 private:
  std::uint32_t previous_type_ = 0;  // type of the last word read (CONTINUED's check)
};

}  // namespace evlife::io
