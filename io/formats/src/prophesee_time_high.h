// The TIME_HIGH counter of Prophesee EVT 2.0 and 2.1: 28 bits holding bits
// 6-33 of the time in µs (it wraps every 2^34 µs, ~4 h 46 min), unwrapped
// here to 64 bits. Event words carry bits 0-5.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "evlife/io/event_reader.h"

#include "wrapping_counter.h"

namespace evlife::io {

class PropheseeTimeHigh {
 public:
  /// A TIME_HIGH word's 28-bit value.
  void update(std::uint64_t raw) noexcept {
    us_ = counter_.unwrap(raw) * 64;
    seen_ = true;
  }
  /// The time of the last TIME_HIGH, µs (its 6 low bits zero).
  std::int64_t us() const noexcept { return us_; }
  /// False before the stream's first TIME_HIGH: "decoding of the event
  /// stream should start after receiving the first event of type
  /// EVT_TIME_HIGH" (Prophesee's EVT 2.0 / 2.1 specifications); the events
  /// before it (a file cut mid-stream) have no time and are skipped.
  bool seen() const noexcept { return seen_; }
  static std::string wrap_note() { return WrappingCounter<28>::wrap_note(64); }

 private:
  WrappingCounter<28> counter_;
  std::int64_t us_ = 0;
  bool seen_ = false;
};

/// What a Prophesee stream skipped, by kind (EventReader::skipped_record_kinds()).
/// (`before_address`: EVT 3.0's events before the first row or vector base.)
inline std::vector<SkippedKindCount> prophesee_skipped_kinds(std::uint64_t triggers, std::uint64_t others,
                                                             std::uint64_t before_time_base,
                                                             std::uint64_t before_address = 0) {
  std::vector<SkippedKindCount> kinds;
  if (triggers > 0) kinds.push_back({"trigger", triggers});
  if (others > 0) kinds.push_back({"other-or-continued", others});
  if (before_time_base > 0) kinds.push_back({"event-before-the-first-time-high", before_time_base});
  if (before_address > 0) kinds.push_back({"event-before-its-row-or-vector-base", before_address});
  return kinds;
}

}  // namespace evlife::io
