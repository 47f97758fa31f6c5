// The one EVT 3.0 word decoder of the project, shared by the RAW file reader
// (evt3_reader.cpp) and the ROS `evt3` payloads (ros_payloads.cpp). State
// persists across calls: a stream may be cut anywhere between words.
//
// Words are little-endian u16, type in the top 4 bits. State words set the
// row (ADDR_Y 0), the time (TIME_LOW 6: bits 0-11, TIME_HIGH 8: bits 12-23, a
// 24-bit counter unwrapped to 64 bits: a drop of TIME_HIGH by half its range
// or more is a wrap; a repeated TIME_HIGH keeps TIME_LOW's bits) and a vector
// base (VECT_BASE_X 3: x + polarity); events before the first TIME_HIGH have
// no time and are skipped and counted, as OpenEB's decoder does; events
// come from ADDR_X 2 (one event) and VECT_12 4 / VECT_8 5 (a bit mask of up to
// 12 / 8 events at base x + i, base x then advances by 12 / 8). EXT_TRIGGER 10
// is counted (and handed to a TriggerSink if set); OTHERS 14 and the
// CONTINUED_4 7 / CONTINUED_12 15 words that go on from it are skipped and
// counted. A CONTINUED word after any other word is a fault: it continues
// nothing, and corrupt data (0xFF bytes) reads as CONTINUED_12. So is a
// second zero word in a row (row y=0 set again with nothing between: the
// zeros a file system leaves where a write was lost). Times are in µs.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "evlife/algo/event.h"

namespace evlife::io {

/// Receives EVT 3.0 EXT_TRIGGER words (rare: a virtual call each is fine).
class Evt3TriggerSink {
 public:
  virtual ~Evt3TriggerSink() = default;
  virtual void on_trigger(std::int64_t t_us, int edge, int id) = 0;
};

class Evt3Decoder {
 public:
  static constexpr std::size_t kWordBytes = 2;
  static constexpr std::size_t kMaxEventsPerWord = 12;

  /// Coordinates must lie inside width x height (at most 2048 x 2048).
  void set_geometry(std::uint32_t width, std::uint32_t height) noexcept;

  struct Result {
    std::size_t words = 0;   ///< words consumed
    std::size_t events = 0;  ///< events written to out
    bool fault = false;      ///< the word at index `words` is bad: see fault_message()
    /// The fault began one word earlier (the first of two zero words, maybe
    /// the last word of the previous call): where the bad data starts.
    bool fault_began_a_word_before = false;
  };

  /// Decodes up to `words` words from `bytes` into `out`, stopping while a
  /// whole word's events (kMaxEventsPerWord) still fit, or at a bad word.
  Result decode(const std::uint8_t* bytes, std::size_t words, std::span<Event> out);

  /// What the last faulting decode() found wrong (allocates: error path only).
  std::string fault_message() const;

  std::uint64_t trigger_count() const noexcept { return trigger_count_; }
  std::uint64_t other_count() const noexcept { return other_count_; }
  /// Events before the stream's first TIME_HIGH (a file cut mid-stream): skipped.
  std::uint64_t before_time_base_count() const noexcept { return before_time_base_count_; }
  /// Events (after the time base) before the stream's first ADDR_Y, or vector
  /// events before its first VECT_BASE_X: row or column unknown, skipped.
  std::uint64_t before_address_count() const noexcept { return before_address_count_; }
  void set_trigger_sink(Evt3TriggerSink* sink) noexcept { trigger_sink_ = sink; }

 private:
  std::uint32_t width_ = 2048;
  std::uint32_t height_ = 2048;
  std::uint32_t y_ = 0;
  std::uint32_t base_x_ = 0;
  std::int8_t vector_p_ = 1;
  std::uint32_t time_high_ = 0;  // last 12-bit TIME_HIGH
  std::int64_t wrap_us_ = 0;     // added per 24-bit wrap
  std::int64_t t_us_ = 0;
  std::uint64_t trigger_count_ = 0;
  std::uint64_t other_count_ = 0;
  std::uint64_t before_time_base_count_ = 0;
  std::uint64_t before_address_count_ = 0;
  bool has_time_base_ = false;  // a TIME_HIGH was seen
  bool has_y_ = false;          // an ADDR_Y was seen
  bool has_base_x_ = false;     // a VECT_BASE_X was seen
  Evt3TriggerSink* trigger_sink_ = nullptr;
  std::uint16_t fault_word_ = 0;
  // The last word decoded (CONTINUED's check reads its type, the zero-fill
  // check whether it was 0x0000); before the first, none: no type, not zero.
  static constexpr std::uint32_t kNoWord = 0x10000;
  std::uint32_t previous_word_ = kNoWord;
};

}  // namespace evlife::io
