// Real-time settings of the engine's threads (evlife run --cpus,
// --rt-priority, --lock-memory). Applied by Engine::run() before any event
// moves: each thread is created waiting at a gate, gets its CPU and
// scheduling policy from the creating thread, and only then starts. Anything
// refused (no CAP_SYS_NICE / RLIMIT_RTPRIO, a CPU outside the process's
// affinity mask, no CAP_IPC_LOCK / RLIMIT_MEMLOCK too small) ends the run
// before it starts, with RunStatus::realtime_error naming the setting and the
// reason: never a silent fallback to default scheduling.
#pragma once

#include <string>
#include <vector>

namespace evlife::engine {

struct RealtimeOptions {
  /// CPUs to pin the threads to, one each in this order, cycling through the
  /// list: source, worker 0 .. N-1, merger backstop, render. Empty: not pinned.
  std::vector<int> cpus;
  /// SCHED_FIFO priority (1..99) of the source, worker and merger threads
  /// (the render thread and the monitor keep the default policy); 0: none.
  int rt_priority = 0;
  /// mlockall(MCL_CURRENT | MCL_FUTURE) before the threads start: every pool,
  /// the estimators' state and the queues (allocated by then) are faulted in
  /// and locked, and so is each thread's stack as it is created. The lock is
  /// the process's: it stays after run() returns (munlockall() to undo),
  /// except when a setting was refused (then run() undoes it).
  bool lock_memory = false;

  bool any() const noexcept { return !cpus.empty() || rt_priority != 0 || lock_memory; }
};

/// Empty when usable, else a message naming the field.
std::string validate_realtime_options(const RealtimeOptions& options);

/// "0,2-3" -> {0, 2, 3}; throws std::invalid_argument naming the bad part.
std::vector<int> parse_cpu_list(const std::string& text);

}  // namespace evlife::engine
