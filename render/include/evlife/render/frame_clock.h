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

}  // namespace evlife::render
