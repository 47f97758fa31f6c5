// The instants of a frame rate, one rule for `evlife render --fps` and the
// render thread of `evlife run --fps`, so both draw the same frames: frame k
// at from_us + k / fps (rounded to the µs, not accumulated, so no drift).
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>

#include "evlife/algo/event.h"

namespace evlife::render {

/// The slowest frame rate taken (a frame each 11.6 days of recording): a
/// frame's instant, k * 1e6 / fps, stays far within int64 µs for any k the
/// times of a recording reach (at 1e-13 fps one interval overflowed it, and
/// frame_count_through() looped forever).
inline constexpr double kMinFps = 1e-6;

/// later_us - earlier_us (later >= earlier), INT64_MAX when the span is
/// longer than the clock holds: a file's times may span all of int64.
inline std::int64_t clock_span_us(std::int64_t earlier_us, std::int64_t later_us) noexcept {
  const std::uint64_t span = span_us(earlier_us, later_us);
  return span > static_cast<std::uint64_t>(INT64_MAX) ? INT64_MAX : static_cast<std::int64_t>(span);
}

/// t_us + offset_us (offset >= 0), INT64_MAX past the clock's end.
inline std::int64_t clock_add_us(std::int64_t t_us, std::int64_t offset_us) noexcept {
  std::int64_t sum = 0;
  return __builtin_add_overflow(t_us, offset_us, &sum) ? INT64_MAX : sum;
}

/// Frame k's instant; INT64_MAX, never reached, for one past the clock's end.
inline std::int64_t frame_instant_us(std::int64_t from_us, std::uint64_t k, double fps) noexcept {
  const double offset_us = static_cast<double>(k) * 1e6 / fps;
  return offset_us < 0x1p63 ? clock_add_us(from_us, std::llround(offset_us)) : INT64_MAX;
}

/// Frames of `fps` from `from_us` up to `to_us` inclusive (0 when to < from):
/// counted on the rule above, so --to 0.2 at 10 fps draws its frame at
/// 0.2 s (a count of (to - from) * 1e-6 * fps floored gave 1.999... -> 1).
inline std::uint64_t frame_count_through(std::int64_t from_us, std::int64_t to_us, double fps) noexcept {
  if (to_us < from_us) return 0;
  // A frame past the clock's end (INT64_MAX) is none; the estimate is within
  // a few frames of the count (double's precision at 2^63 us: ~2 ms).
  const auto drawn = [&](std::uint64_t j) {
    const std::int64_t t = frame_instant_us(from_us, j, fps);
    return t <= to_us && t != INT64_MAX;
  };
  const double estimate = std::floor(static_cast<double>(clock_span_us(from_us, to_us)) * fps / 1e6);
  auto k = static_cast<std::uint64_t>(std::min(estimate, 1.8e19));
  while (drawn(k + 1)) ++k;
  while (k > 0 && !drawn(k)) --k;
  return k + 1;
}

/// Frames k, k + 1, ... of `fps` from `from_us` at instants before
/// `next_event_us`: those a frame rate draws before it.
inline std::uint64_t frames_before(std::int64_t from_us, std::uint64_t k, std::int64_t next_event_us,
                                   double fps) noexcept {
  const std::uint64_t through = frame_count_through(from_us, next_event_us - 1, fps);
  return through > k ? through - k : 0;
}

/// A stretch without events ahead of a frame rate (times from the first
/// event): a timestamp outlier would have `evlife render --fps` and
/// `run --fps` draw millions of empty frames, so it is said before them.
struct EventGap {
  std::int64_t from_us = 0;        ///< the next frame's instant
  std::int64_t next_event_us = 0;  ///< the next event
  std::uint64_t empty_frames = 0;  ///< frames before it, that one included
  /// "no event from 0.333333 s to 99999.999981 s (the next event): 2999990
  /// empty frames at 30 fps come first; a timestamp outlier?"
  std::string text(double fps) const {
    char out[240];
    std::snprintf(out, sizeof out,
                  "no event from %.6f s to %.6f s (the next event): %llu empty frames at %g fps come first; a "
                  "timestamp outlier?",
                  static_cast<double>(from_us) * 1e-6, static_cast<double>(next_event_us) * 1e-6,
                  static_cast<unsigned long long>(empty_frames), fps);
    return out;
  }
};

/// A gap of this many empty frames (an hour at 30 fps), wherever it is and
/// however long in seconds, ends `evlife render` as an input fault unless --to
/// asks for them: a timestamp outlier would otherwise fill the disk with
/// millions of blank frames.
constexpr std::uint64_t kEventGapStopFrames = 100'000;

/// Said when it holds at least this many frames and lasts kEventGapNoticeUs (event.h).
constexpr std::uint64_t kEventGapNoticeFrames = 1000;
inline std::optional<EventGap> event_gap_to_notice(std::int64_t from_us, std::int64_t next_event_us,
                                                   std::uint64_t empty_frames) noexcept {
  if (empty_frames < kEventGapNoticeFrames || next_event_us - from_us < kEventGapNoticeUs) return std::nullopt;
  return EventGap{from_us, next_event_us, empty_frames};
}

/// The one rule of `evlife render --fps` and `run --fps` for the stretch
/// after clock frame k (of `fps` from `from_us`), whose events are all in:
/// frame k shows the last of them and is drawn; the frames after it and
/// before the next event are empty. Said when noticeable; too_long
/// (kEventGapStopFrames or more) ends `render` before them and is skipped by
/// `run`. Times from the first event.
struct GapAhead {
  std::optional<EventGap> gap;  ///< empty: nothing to say
  bool too_long = false;
};
inline GapAhead gap_after_frame(std::int64_t from_us, std::uint64_t k, double fps,
                                std::int64_t next_event_us) noexcept {
  const std::uint64_t empty = frames_before(from_us, k + 1, next_event_us, fps);
  const std::int64_t next_frame_us = frame_instant_us(from_us, k + 1, fps);
  GapAhead ahead;
  ahead.too_long = empty >= kEventGapStopFrames;
  ahead.gap = ahead.too_long ? std::optional<EventGap>(EventGap{next_frame_us, next_event_us, empty})
                             : event_gap_to_notice(next_frame_us, next_event_us, empty);
  return ahead;
}

}  // namespace evlife::render
