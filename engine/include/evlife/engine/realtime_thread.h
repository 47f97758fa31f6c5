// The system calls behind RealtimeOptions (Linux). Each returns an empty
// string on success, else what was refused and why (errno text and the
// permission it needs). Used by Engine::run(); tests call them directly.
#pragma once

#include <pthread.h>

#include <string>

#include "evlife/engine/realtime_options.h"

namespace evlife::engine {

/// mlockall(MCL_CURRENT | MCL_FUTURE).
std::string lock_process_memory();
/// munlockall() (undoes it when a later setting is refused).
void unlock_process_memory() noexcept;

/// Pins `thread` to `cpu` (cpu < 0: leave as is).
std::string pin_thread(pthread_t thread, int cpu);

/// SCHED_FIFO at `priority` for `thread` (priority 0: leave as is).
std::string set_fifo_priority(pthread_t thread, int priority);

/// Tries each setting of `options` on a thread of its own (and mlockall,
/// undone): what Engine::run() would refuse, said before a command touches
/// its output. Empty when all pass (run() checks again as it applies them).
std::string probe_realtime_options(const RealtimeOptions& options);

/// Locked bytes of this process (VmLck of /proc/self/status), -1 unknown.
long long locked_memory_bytes();

}  // namespace evlife::engine
