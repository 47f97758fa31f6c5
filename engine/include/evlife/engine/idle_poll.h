// Idle polling that gives way under load. A thread that waits for work by
// polling (yielding the core between looks) saves the wake-up of a sleeping
// thread (on a VM whose idle vCPU halts: ~30 us median, 60-100 us p99), but
// only while the core is otherwise idle: when another runnable thread shares
// it, each yield hands the core over and pushes the poller back in the
// kernel's queue (EEVDF), so the poller comes back late, after whole time
// slices of the other thread, and sleeping until woken is the faster way.
// poll_until() therefore stops polling as soon as one look comes much later
// than the previous one (the core was taken meanwhile).
#pragma once

#include <cstdint>
#include <thread>

#include "evlife/engine/monotonic_clock.h"

namespace evlife::engine {

/// A gap between two looks longer than this means another thread ran.
inline constexpr std::int64_t kPollPreemptedNs = 20'000;

/// Polls `done()` until it holds (true) or until `until_ns` (steady clock)
/// or until another thread took the core between two looks (false: the
/// caller then sleeps). Never allocates or throws.
template <class Done>
bool poll_until(Done&& done, std::int64_t until_ns) noexcept {
  std::int64_t prev = monotonic_ns();
  while (!done()) {
    if (prev >= until_ns) return false;
    std::this_thread::yield();
    const std::int64_t now = monotonic_ns();
    if (now - prev > kPollPreemptedNs) return done();
    prev = now;
  }
  return true;
}

}  // namespace evlife::engine
