#include "allocator_safe_fork.h"

#include <dirent.h>
#include <unistd.h>

#include <cerrno>

// g++ says __SANITIZE_ADDRESS__, clang __has_feature(address_sanitizer).
#if defined(__SANITIZE_ADDRESS__)
#define EVLIFE_ADDRESS_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define EVLIFE_ADDRESS_SANITIZER 1
#endif
#endif

#ifdef EVLIFE_ADDRESS_SANITIZER
// The sanitizer runtime's own locking (asan_allocator.cpp: the functions
// that lock a malloc zone; sanitizer_stackdepot.h), weak: a runtime without
// them leaves them null. NOLINTBEGIN(bugprone-reserved-identifier,readability-identifier-naming)
namespace __asan {
__attribute__((weak)) void asan_mz_force_lock();
__attribute__((weak)) void asan_mz_force_unlock();
}  // namespace __asan
namespace __sanitizer {
__attribute__((weak)) void StackDepotLockAll();
__attribute__((weak)) void StackDepotUnlockAll();
}  // namespace __sanitizer
// NOLINTEND(bugprone-reserved-identifier,readability-identifier-naming)
#endif

namespace evlife::io::detail {

#ifdef EVLIFE_ADDRESS_SANITIZER
namespace {

// Whether this process runs threads besides the caller (true when /proc
// cannot say).
bool other_threads_run() {
  DIR* tasks = opendir("/proc/self/task");
  if (tasks == nullptr) return true;
  int threads = 0;
  while (const dirent* entry = readdir(tasks)) threads += entry->d_name[0] != '.';
  closedir(tasks);
  return threads != 1;
}

}  // namespace
#endif

pid_t allocator_safe_fork() {
#ifdef EVLIFE_ADDRESS_SANITIZER
  if (__asan::asan_mz_force_lock != nullptr && __asan::asan_mz_force_unlock != nullptr &&
      __sanitizer::StackDepotLockAll != nullptr && __sanitizer::StackDepotUnlockAll != nullptr) {
    // (No allocation between lock and unlock: this thread would wait on itself.)
    __asan::asan_mz_force_lock();
    __sanitizer::StackDepotLockAll();
    const pid_t forked = fork();
    __sanitizer::StackDepotUnlockAll();  // in the parent and in the child
    __asan::asan_mz_force_unlock();
    return forked;
  }
  if (other_threads_run()) {
    errno = EAGAIN;
    return -1;
  }
#endif
  return fork();
}

}  // namespace evlife::io::detail
