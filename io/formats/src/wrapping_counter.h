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

namespace evlife::io {

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

 private:
  static constexpr std::int64_t kRange = std::int64_t{1} << Bits;
  static constexpr std::uint64_t kHalf = std::uint64_t{1} << (Bits - 1);
  std::uint64_t last_ = 0;
  std::int64_t base_ = 0;
  bool seen_ = false;
};

}  // namespace evlife::io
