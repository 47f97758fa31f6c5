// The TIME_HIGH counter of Prophesee EVT 2.0 and 2.1: 28 bits holding bits
// 6-33 of the time in µs (it wraps every 2^34 µs, ~4 h 46 min), unwrapped
// here to 64 bits. Event words carry bits 0-5.
#pragma once

#include <cstdint>
#include <string>

#include "wrapping_counter.h"

namespace evlife::io {

class PropheseeTimeHigh {
 public:
  /// A TIME_HIGH word's 28-bit value.
  void update(std::uint64_t raw) noexcept { us_ = counter_.unwrap(raw) * 64; }
  /// The time of the last TIME_HIGH, µs (its 6 low bits zero).
  std::int64_t us() const noexcept { return us_; }
  static std::string wrap_note() { return WrappingCounter<28>::wrap_note(64); }

 private:
  WrappingCounter<28> counter_;
  std::int64_t us_ = 0;
};

}  // namespace evlife::io
