// The TIME_HIGH counter of Prophesee EVT 2.0 and 2.1: 28 bits holding bits
// 6-33 of the time in µs (it wraps every 2^34 µs, ~4 h 46 min), unwrapped
// here to 64 bits. Event words carry bits 0-5.
#pragma once

#include <cstdint>

namespace evlife::io {

class PropheseeTimeHigh {
 public:
  /// A TIME_HIGH word's 28-bit value.
  void update(std::uint64_t raw) noexcept {
    // A drop by more than half the range is a wrap of the 28-bit counter.
    if (raw < raw_ && raw_ - raw > kRange / 2) wrap_us_ += static_cast<std::int64_t>(kRange << 6);
    raw_ = raw;
    us_ = wrap_us_ + static_cast<std::int64_t>(raw << 6);
  }
  /// The time of the last TIME_HIGH, µs (its 6 low bits zero).
  std::int64_t us() const noexcept { return us_; }

 private:
  static constexpr std::uint64_t kRange = std::uint64_t{1} << 28;
  std::uint64_t raw_ = 0;
  std::int64_t us_ = 0;
  std::int64_t wrap_us_ = 0;
};

}  // namespace evlife::io
