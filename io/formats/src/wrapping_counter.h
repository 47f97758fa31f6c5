// A sensor clock of `Bits` bits that wraps (AEDAT 2.0 and DAT timestamps,
// the 28-bit TIME_HIGH of EVT 2.0 and 2.1), unwrapped to 64 bits. Each value is taken as the
// shorter step from the last one, modulo the range: a drop by more than half
// the range is a wrap forward, and a rise by more than half the range is a
// step *back* across a wrap. So one corrupt high bit unwraps to a time before
// its predecessor, which the checked reader reports (file, offset, event
// index), instead of shifting every later event by the range (71.6 min for
// 32 µs bits, 4.8 h for TIME_HIGH) with no error. EVT 3.0's 12-bit TIME_HIGH
// keeps the one-sided rule: its half range, 8.4 s, is a gap a quiet sensor
// can leave between two TIME_HIGH words.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>

namespace evlife::io {

/// The note for EventReader::clock_wrap_note of a `bits`-bit clock counting
/// `unit_us` µs: a step back may also be a gap of more than half its range.
inline std::string clock_wrap_note(unsigned bits, std::int64_t unit_us) {
  const double range_min = static_cast<double>(std::int64_t{1} << bits) * static_cast<double>(unit_us) / 60e6;
  char text[200];
  std::snprintf(text, sizeof text,
                "the format's %u-bit clock wraps every %.1f min, so a gap of more than %.1f min between "
                "two events reads as a step back too",
                bits, range_min, range_min / 2);
  return text;
}

template <unsigned Bits>
class WrappingCounter {
 public:
  /// `raw` (its low Bits bits) unwrapped, in the counter's units.
  std::int64_t unwrap(std::uint64_t raw) noexcept {
    if (seen_) {
      if (raw < last_ && last_ - raw > kHalf) base_ += kRange;  // forward across a wrap
      if (raw > last_ && raw - last_ > kHalf) base_ -= kRange;  // back across a wrap: corrupt
    }
    seen_ = true;
    last_ = raw;
    return base_ + static_cast<std::int64_t>(raw);
  }

  /// clock_wrap_note() of this counter counting `unit_us` µs.
  static std::string wrap_note(std::int64_t unit_us) { return clock_wrap_note(Bits, unit_us); }

 private:
  static constexpr std::int64_t kRange = std::int64_t{1} << Bits;
  static constexpr std::uint64_t kHalf = std::uint64_t{1} << (Bits - 1);
  std::uint64_t last_ = 0;
  std::int64_t base_ = 0;
  bool seen_ = false;
};

}  // namespace evlife::io
