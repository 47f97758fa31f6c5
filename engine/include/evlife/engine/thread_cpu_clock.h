#pragma once

#include <cstdint>
#include <ctime>

namespace evlife::engine {

/// CPU time of the calling thread, ns (vDSO on Linux: no system call).
inline std::int64_t thread_cpu_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

}  // namespace evlife::engine
