// A tiny counter-free generator seeded per event, so that RANSAC draws depend
// only on (seed, event) and never on which other events a worker has seen.
#pragma once

#include <cstdint>

#include "evlife/algo/event.h"

namespace evlife::detail {

constexpr std::uint64_t splitmix64(std::uint64_t z) noexcept {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

class EventRng {
 public:
  EventRng(std::uint64_t seed, const Event& e) noexcept
      : state_(splitmix64(seed ^ splitmix64(static_cast<std::uint64_t>(e.t_us) ^
                                            (static_cast<std::uint64_t>(e.x) << 40) ^
                                            (static_cast<std::uint64_t>(e.y) << 20) ^
                                            (e.p > 0 ? 1ULL << 62 : 0ULL)))) {}

  /// Uniform integer in [0, n), n > 0 (multiply-shift: no modulo).
  /// One step of a 64-bit LCG; its high 32 bits are well mixed, which is
  /// all that picking one of <= 224 samples needs.
  std::uint32_t below(std::uint32_t n) noexcept {
    state_ = state_ * kMultiplier + kIncrement;
    const std::uint64_t r = state_ >> 32;
    return static_cast<std::uint32_t>((r * n) >> 32);
  }

  static constexpr std::uint64_t kMultiplier = 6364136223846793005ULL;
  static constexpr std::uint64_t kIncrement = 1442695040888963407ULL;
  /// `steps` steps of the LCG as one: state -> multiplier * state + increment
  /// (for drawing several values at once; plane_draws.cpp).
  struct Jump {
    std::uint64_t multiplier, increment;
  };
  static constexpr Jump jump(int steps) noexcept {
    Jump j{1, 0};
    for (int k = 0; k < steps; ++k) j = {j.multiplier * kMultiplier, j.increment * kMultiplier + kIncrement};
    return j;
  }
  std::uint64_t state() const noexcept { return state_; }
  void set_state(std::uint64_t state) noexcept { state_ = state; }

 private:
  std::uint64_t state_;
};

}  // namespace evlife::detail
