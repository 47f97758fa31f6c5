#include "evlife/engine/realtime_thread.h"

#include <sched.h>
#include <sys/mman.h>
#include <sys/resource.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <future>
#include <string>
#include <thread>

namespace evlife::engine {
namespace {
std::string rlimit_text(int resource) {
  rlimit l{};
  if (getrlimit(resource, &l) != 0) return "unknown";
  if (l.rlim_cur == RLIM_INFINITY) return "unlimited";
  return std::to_string(static_cast<unsigned long long>(l.rlim_cur));
}
}  // namespace

std::string lock_process_memory() {
  if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) return {};
  const int err = errno;
  return std::string("--lock-memory: mlockall(MCL_CURRENT | MCL_FUTURE) failed: ") + std::strerror(err) +
         " (needs CAP_IPC_LOCK, or RLIMIT_MEMLOCK above the process's memory; RLIMIT_MEMLOCK is " +
         rlimit_text(RLIMIT_MEMLOCK) + " bytes)";
}

void unlock_process_memory() noexcept { munlockall(); }

std::string pin_thread(pthread_t thread, int cpu) {
  if (cpu < 0) return {};
  if (cpu >= CPU_SETSIZE) return "--cpus: CPU " + std::to_string(cpu) + " is beyond CPU_SETSIZE";
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  const int err = pthread_setaffinity_np(thread, sizeof set, &set);
  if (err == 0) return {};
  return "--cpus: cannot pin a thread to CPU " + std::to_string(cpu) + ": " + std::strerror(err) +
         (err == EINVAL ? " (not an online CPU of this process's affinity mask; see `taskset -p $$`)" : "");
}

std::string set_fifo_priority(pthread_t thread, int priority) {
  if (priority == 0) return {};
  sched_param param{};
  param.sched_priority = priority;
  const int err = pthread_setschedparam(thread, SCHED_FIFO, &param);
  if (err == 0) return {};
  return "--rt-priority: SCHED_FIFO priority " + std::to_string(priority) + " refused: " +
         std::strerror(err) +
         (err == EPERM ? " (needs CAP_SYS_NICE, or RLIMIT_RTPRIO >= the priority; `ulimit -r` is " +
                             rlimit_text(RLIMIT_RTPRIO) + ")"
                       : "");
}

std::string probe_realtime_options(const RealtimeOptions& options) {
  if (options.lock_memory) {
    if (std::string refused = lock_process_memory(); !refused.empty()) return refused;
    unlock_process_memory();
  }
  if (options.cpus.empty() && options.rt_priority == 0) return {};
  // A thread parked until it has been tried: the settings apply to a live one.
  std::promise<void> release;
  std::thread probe([done = release.get_future()]() mutable { done.wait(); });
  std::string refused;
  for (const int cpu : options.cpus) {
    if (refused.empty()) refused = pin_thread(probe.native_handle(), cpu);
  }
  if (refused.empty()) refused = set_fifo_priority(probe.native_handle(), options.rt_priority);
  release.set_value();
  probe.join();
  return refused;
}

long long locked_memory_bytes() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmLck:", 0) == 0) return std::stoll(line.substr(6)) * 1024;
  }
  return -1;
}

}  // namespace evlife::engine
