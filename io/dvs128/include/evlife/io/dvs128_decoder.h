// Turns the DVS128's 4-byte USB event words into Events. Pure: no I/O, no
// allocation, no exceptions, bounded work per word.
//
// Axes (same as the AEDAT2 reader and libcaer): x = 127 - raw_x (0 = left),
// y = 127 - raw_y (0 = top row). Polarity: raw bit 0 = 0 -> ON (+1).
//
// Time: 64-bit microseconds = 14-bit word timestamp + 0x4000 us per wrap word
// seen. A wrap word is checked before a reset word (a word with both flags is
// a wrap). A reset word (the camera's answer to request 0xBB) zeroes the
// running wrap offset; so that time never runs backwards for the estimator,
// the stream after a reset continues from the last emitted timestamp (at the
// start of a run, before any event, that is 0: identical to libcaer).
// Sync / external-input words are counted, never emitted as pixels.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "evlife/algo/event.h"

namespace evlife::io {

struct Dvs128DecoderCounters {
  std::uint64_t words = 0;          ///< complete 4-byte words consumed
  std::uint64_t pixel_events = 0;   ///< emitted as Events
  std::uint64_t sync_events = 0;    ///< bit 15 of the address: external input
  std::uint64_t wraps = 0;          ///< timestamp wrap words
  std::uint64_t resets = 0;         ///< timestamp reset words
  std::uint64_t time_regressions = 0;  ///< words older than the previous event (clamped)
};

class Dvs128Decoder {
 public:
  struct Result {
    std::size_t bytes_consumed = 0;
    std::size_t events_written = 0;
  };

  /// Decodes whole words from `bytes` into `out` until either runs out. A
  /// trailing partial word (fewer than 4 bytes) is kept and completed by the
  /// next call, so transfers need not be word aligned. Stops early when `out`
  /// is full: call again with bytes.subspan(result.bytes_consumed).
  Result decode(std::span<const std::uint8_t> bytes, std::span<Event> out) noexcept;

  /// Back to the start-of-stream state (offset 0, counters zero).
  void reset() noexcept { *this = Dvs128Decoder{}; }

  const Dvs128DecoderCounters& counters() const noexcept { return counters_; }
  /// Bytes of an incomplete word waiting for the next transfer (0..3).
  std::size_t pending_bytes() const noexcept { return partial_size_; }

 private:
  /// Handles one word; returns true when it wrote an event to `out`.
  bool decode_word(const std::uint8_t* w, Event& out) noexcept;

  std::int64_t wrap_offset_us_ = 0;  ///< sum of wraps since the last reset
  std::int64_t epoch_us_ = 0;        ///< time at the last reset
  std::int64_t last_t_us_ = 0;       ///< last emitted timestamp
  std::uint8_t partial_[4] = {};
  std::size_t partial_size_ = 0;
  Dvs128DecoderCounters counters_;
};

}  // namespace evlife::io
