// The estimator's time surface in 32 bits: each pixel's time relative to a
// rolling epoch (`t_rel`), next to the timing noise the gather reads with it,
// in 8 bytes (LifetimeEstimator::SurfacePixel) (a window row of 5 pixels is one cache line in two, was always two
// with 64-bit times: the gather on large sensors is bound by cache misses).
//
// Exactness: a stored time is t_us - epoch, exact while it fits in 32 bits;
// differences of times, the only thing the estimator reads, are the same as
// with 64-bit times. The epoch moves (rebase(), O(pixels)) when a new event's
// relative time leaves [kLowestRel, kHighestRel]: the new event then sits at
// kRebaseRel, 2^30 us (~18 min) after the epoch, so a rebase happens at
// most once per ~18 min of recording. Times that fall out of the range
// saturate: older than ~54 min before the rebase to kOldestRel (still a past
// event, but its age no longer exact), or, after a jump back in time by more
// than ~18 min, newer ones to kHighestRel. Only then can the result differ from
// 64-bit times.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>

namespace evlife::detail {

constexpr std::int32_t kNeverRel = std::numeric_limits<std::int32_t>::min();
constexpr std::int32_t kOldestRel = kNeverRel + 1;
constexpr std::int32_t kHighestRel = std::numeric_limits<std::int32_t>::max();
constexpr std::int32_t kLowestRel = kOldestRel;
constexpr std::int64_t kRebaseRel = std::int64_t{1} << 30;

/// a - b in double, rounded once from the exact difference: two event times
/// (|t| <= 2^62, an epoch 2^30 below one) may lie more than 2^63 apart, where
/// int64 subtraction overflows; only those are subtracted in double (times
/// near 2^62 converted first lost up to 1024 us: prediction errors of 0).
inline double difference_us(std::int64_t a, std::int64_t b) noexcept {
  std::int64_t d = 0;
  if (!__builtin_sub_overflow(a, b, &d)) return static_cast<double>(d);
  return static_cast<double>(a) - static_cast<double>(b);
}

/// True when t_us - epoch_us fits the plane (no rebase needed).
inline bool fits_epoch(std::int64_t t_us, std::int64_t epoch_us) noexcept {
  // Unsigned compare of the offset from kLowestRel: one branch for both ends.
  // (Unsigned, so that times more than 2^63 apart wrap, well defined, to an
  // offset outside the range instead of overflowing.)
  const auto off = static_cast<std::uint64_t>(t_us) - static_cast<std::uint64_t>(epoch_us) -
                   static_cast<std::uint64_t>(std::int64_t{kLowestRel});
  return off <= static_cast<std::uint64_t>(std::int64_t{kHighestRel} - kLowestRel);
}

/// Moves the epoch so that t_us sits at kRebaseRel; shifts every stored time,
/// saturating those that leave the range. Returns the new epoch.
template <class Pixel>
std::int64_t rebase(std::span<Pixel> plane, std::int64_t epoch_us, std::int64_t t_us) noexcept {
  const std::int64_t new_epoch = t_us - kRebaseRel;
  // A shift beyond 2^40 us saturates every stored time as the exact one
  // would (the range is 2^32 wide); clamped, neither it nor a moved time can
  // overflow (epochs up to 2^63 apart).
  constexpr std::int64_t kShiftBound = std::int64_t{1} << 40;
  std::int64_t shift = 0;
  if (__builtin_sub_overflow(new_epoch, epoch_us, &shift)) shift = new_epoch > epoch_us ? kShiftBound : -kShiftBound;
  shift = shift > kShiftBound ? kShiftBound : (shift < -kShiftBound ? -kShiftBound : shift);
  for (Pixel& p : plane) {
    // Never fired, or saturated older than the range: stays so. (Moved back
    // by a backwards rebase, a saturated time read as recent, up to the
    // newest possible: ages below zero.)
    if (p.t_rel == kNeverRel || p.t_rel == kOldestRel) continue;
    const std::int64_t moved = static_cast<std::int64_t>(p.t_rel) - shift;
    p.t_rel = moved < kOldestRel ? kOldestRel : (moved > kHighestRel ? kHighestRel : static_cast<std::int32_t>(moved));
  }
  return new_epoch;
}

}  // namespace evlife::detail
