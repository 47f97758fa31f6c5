// fork() for a child that allocates memory (libhdf5 does, reading) while the
// parent may run other threads: the allocator's locks must not be copied
// held by a thread the child does not have, or the child waits on them for
// ever. glibc's malloc (the release builds') locks itself around fork();
// the AddressSanitizer of clang 14 (Debian 12's) does not (later LLVM does):
// its child, forked while another thread refilled its allocation cache,
// waited in malloc inside H5Dread, and a valid file was said to hang the
// library (`evlife run` under the CI's ASan pass, 1 run in 12).
#pragma once

#include <sys/types.h>

namespace evlife::io::detail {

/// fork(). In an AddressSanitizer build, with the sanitizer's allocator and
/// stack depot locked across it, as later LLVM runtimes do themselves; where
/// that runtime lacks the functions to lock them, a process of several
/// threads does not fork: -1 (errno EAGAIN), and the caller goes without a child.
/// (The lock of ASan's quarantine of freed memory is not among those taken:
/// a child could still wait on it if another thread was moving its freed
/// blocks to the global quarantine at the fork; not seen in 30 runs.)
pid_t allocator_safe_fork();

}  // namespace evlife::io::detail
