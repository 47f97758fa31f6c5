// Cycle counters per stage of LifetimeEstimator::process(), compiled in only
// for bench/stage_costs.cpp (EVLIFE_ESTIMATOR_STAGE_CLOCK defined): every
// other build gets empty inline functions and unchanged code.
#pragma once

#include <cstdint>

#if defined(EVLIFE_ESTIMATOR_STAGE_CLOCK)
#if defined(__x86_64__) || defined(__i386__)
#include <x86intrin.h>
#else
#include <chrono>
#endif
#endif

namespace evlife::detail {

/// head: checks, follower, prediction; gather: window read and the newer
/// half (WindowSamples::gather_newest()); select: the padding; ransac;
/// continuation: continues_an_edge(); refit: least squares and lifetime;
/// tail: burst state, residual rms and the next prediction.
enum class Stage : int { head, gather, select, ransac, continuation, refit, tail, count };

#if defined(EVLIFE_ESTIMATOR_STAGE_CLOCK)
struct StageClock {
  std::uint64_t ticks[static_cast<int>(Stage::count)] = {};
  std::uint64_t entered[static_cast<int>(Stage::count)] = {};
  std::uint64_t last = 0;
};
inline StageClock& stage_clock() noexcept {
  static StageClock clock;
  return clock;
}
inline std::uint64_t stage_ticks() noexcept {
#if defined(__x86_64__) || defined(__i386__)
  return __rdtsc();
#else
  return static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
#endif
}
inline void stage_start() noexcept { stage_clock().last = stage_ticks(); }
inline void stage_end(Stage s) noexcept {
  const std::uint64_t now = stage_ticks();
  StageClock& c = stage_clock();
  c.ticks[static_cast<int>(s)] += now - c.last;
  ++c.entered[static_cast<int>(s)];
  c.last = now;
}
#else
inline void stage_start() noexcept {}
inline void stage_end(Stage) noexcept {}
#endif

}  // namespace evlife::detail
