// A forked child process that calls libhdf5 for its parent, so that a corrupt
// file that crashes or hangs the library (libhdf5 1.10, Debian 12's, has such
// paths in opening and in reading chunks) ends the child, not the caller.
//
// A forked child inherits libhdf5's global lock (a thread-safe build's, as
// Debian's) in whatever state it was: held by another thread of the parent (a
// second reader opening a file, h5py), it is never released in the child. The
// child says it got past the lock; one that does not within a short time is
// stuck on it, not on the file, and is forked again a little later.
#pragma once

#include <sys/types.h>

#include <string>

namespace evlife::io::detail {

/// Forks a child that resets the crash signals to their default action (a
/// crash handler inherited from the parent, a sanitizer's or a fuzzer's,
/// would report the child's crash as the parent's), ignores the signals that
/// ask a process to stop (the parent's to act on), takes libhdf5's lock once
/// and then runs `body(context)`, which must end with _exit. Returns the
/// child's pid, or -1 when none could be started (no fork, or every child
/// stuck on the library's lock; allocator_safe_fork.h): the caller goes on
/// without a child.
pid_t fork_hdf5_child(void (*body)(void* context), void* context);

/// How a child ended, for an error message: {"crashes", "(signal 11,
/// Segmentation fault)", corrupt}, {"fails hard", "(exit status 1)",
/// corrupt} (a sanitizer's report of the crash), {"was killed", "(signal 9,
/// Killed, from outside)"} (not the file's doing), or empty texts when it
/// exited 0.
struct Hdf5ChildFault {
  std::string verb, detail;
  bool corrupt = false;  // the file's doing: libhdf5 crashed or hung on it
};
Hdf5ChildFault hdf5_child_fault(int wait_status);

/// Whether `child` waits for the disk (state D in /proc/PID/stat): slow
/// storage (a network file system, a spun-down disk), not a hang, so the
/// children's time limits start again while it does.
bool waits_for_disk(pid_t child);

}  // namespace evlife::io::detail
