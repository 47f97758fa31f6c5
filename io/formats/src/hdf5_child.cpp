#include "hdf5_child.h"

#include <fcntl.h>
#include <hdf5.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <thread>

#include "allocator_safe_fork.h"

namespace evlife::io::detail {
namespace {

constexpr int kLockWaitMs = 300;  // a child not past the lock by then is stuck on it
constexpr int kForks = 4;
constexpr int kBackoffMs[kForks] = {0, 20, 100, 500};
constexpr unsigned kStuckChildLifeS = 2;  // > kLockWaitMs: the parent kills it first while it lives

// Whether the child wrote its byte within `ms` (false: stuck on the lock).
bool child_ready(int ready_fd, int ms) {
  pollfd fd{ready_fd, POLLIN, 0};
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(ms);
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    const int polled = poll(&fd, 1, static_cast<int>(std::max<std::int64_t>(left.count(), 0)));
    if (polled > 0) {
      char byte = 0;
      return read(ready_fd, &byte, 1) == 1;  // 0: the child ended before (a crash: its status says)
    }
    if (polled == 0 || errno != EINTR) return false;
  }
}

}  // namespace

pid_t fork_hdf5_child(void (*body)(void* context), void* context) {
  for (int attempt = 0; attempt < kForks; ++attempt) {
    std::this_thread::sleep_for(std::chrono::milliseconds(kBackoffMs[attempt]));
    int ready[2];
    if (pipe2(ready, O_CLOEXEC) != 0) return -1;
    const pid_t forked = allocator_safe_fork();
    if (forked < 0) {
      close(ready[0]);
      close(ready[1]);
      return -1;
    }
    if (forked == 0) {
      close(ready[0]);
      for (const int sig : {SIGFPE, SIGSEGV, SIGBUS, SIGILL, SIGABRT}) signal(sig, SIG_DFL);
      // A terminal's Ctrl-C, hang-up or quit reaches the whole process
      // group: the parent decides (an inherited handler, Python's or the
      // CLI's, would act in the child), and its ending ends the child.
      // (SIGTERM too: a service manager's stop reaches every process of the
      // group, and a child that died under its parent's read would turn a
      // clean stop into an input error. SIGKILL ends a child; the parent
      // names it killed from outside.)
      for (const int sig : {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGPIPE}) signal(sig, SIG_IGN);
      // A child stuck on the lock is killed by its parent; one whose parent
      // died first ends by this alarm, cancelled once past the lock.
      signal(SIGALRM, SIG_DFL);
      alarm(kStuckChildLifeS);
      H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // an API call: it takes the library's lock
      alarm(0);
      const char byte = 1;
      if (write(ready[1], &byte, 1) != 1) _exit(0);  // the parent is gone
      close(ready[1]);
      body(context);
      _exit(0);  // no atexit handlers, no flushing of the parent's stdio buffers
    }
    close(ready[1]);
    const bool ready_in_time = child_ready(ready[0], kLockWaitMs);
    close(ready[0]);
    if (ready_in_time || waitpid(forked, nullptr, WNOHANG) == forked) {
      // Past the lock, or already ended (a crash before its byte): the caller
      // reads its status. (WNOHANG reaped an ended one: fork again.)
      if (ready_in_time) return forked;
      continue;
    }
    kill(forked, SIGKILL);
    waitpid(forked, nullptr, 0);
  }
  return -1;
}

bool waits_for_disk(pid_t child) {
  char path[64];
  std::snprintf(path, sizeof path, "/proc/%d/stat", static_cast<int>(child));
  std::FILE* f = std::fopen(path, "r");
  if (f == nullptr) return false;
  char line[512] = {};
  const bool got_line = std::fgets(line, sizeof line, f) != nullptr;
  std::fclose(f);
  const char* end_of_name = got_line ? std::strrchr(line, ')') : nullptr;  // "pid (name) S ..."
  return end_of_name != nullptr && end_of_name[1] == ' ' && end_of_name[2] == 'D';
}

Hdf5ChildFault hdf5_child_fault(int wait_status) {
  if (WIFSIGNALED(wait_status)) {
    const int sig = WTERMSIG(wait_status);
    const std::string which = "(signal " + std::to_string(sig) + ", " + strsignal(sig);
    for (const int crash : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGSYS, SIGTRAP})
      if (sig == crash) return {"crashes", which + ")", true};
    return {"was killed", which + ", from outside)", false};
  }
  // The child exits 0 unless something killed it in its own way (e.g. a
  // sanitizer's report of the same crash): as bad as a signal.
  if (WIFEXITED(wait_status) && WEXITSTATUS(wait_status) != 0)
    return {"fails hard", "(exit status " + std::to_string(WEXITSTATUS(wait_status)) + ")", true};
  return {};
}

}  // namespace evlife::io::detail
