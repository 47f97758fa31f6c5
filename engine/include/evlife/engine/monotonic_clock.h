#pragma once

#include <chrono>
#include <cstdint>

namespace evlife::engine {

/// Steady-clock nanoseconds: the engine's one time base for latency.
inline std::int64_t monotonic_ns() noexcept {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace evlife::engine
