// The instants of a frame rate, one rule for `evlife render --fps` and the
// render thread of `evlife run --fps`, so both draw the same frames: frame k
// at from_us + k / fps (rounded to the µs, not accumulated, so no drift).
#pragma once

#include <cmath>
#include <cstdint>

namespace evlife::render {

inline std::int64_t frame_instant_us(std::int64_t from_us, std::uint64_t k, double fps) noexcept {
  return from_us + std::llround(static_cast<double>(k) * 1e6 / fps);
}

/// Frames of `fps` from `from_us` up to `to_us` inclusive (0 when to < from):
/// counted on the rule above, so --to 0.2 at 10 fps draws its frame at
/// 0.2 s (a count of (to - from) * 1e-6 * fps floored gave 1.999... -> 1).
inline std::uint64_t frame_count_through(std::int64_t from_us, std::int64_t to_us, double fps) noexcept {
  if (to_us < from_us) return 0;
  auto k = static_cast<std::uint64_t>(std::floor(static_cast<double>(to_us - from_us) * fps / 1e6));
  while (frame_instant_us(from_us, k + 1, fps) <= to_us) ++k;
  while (k > 0 && frame_instant_us(from_us, k, fps) > to_us) --k;
  return k + 1;
}

/// A stretch without events ahead of a frame rate is said (a timestamp
/// outlier would draw millions of empty frames) when it holds at least this
/// many frames and lasts this long: `evlife render --fps` and `run --fps`.
constexpr double kEventGapNoticeFrames = 1000.0;
constexpr double kEventGapNoticeS = 60.0;

}  // namespace evlife::render
