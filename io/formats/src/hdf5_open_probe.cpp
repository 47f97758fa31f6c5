#include "hdf5_open_probe.h"

#include <hdf5.h>
#include <poll.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <optional>
#include <thread>

#include "evlife/io/event_reader.h"
#include "hdf5_attributes.h"

namespace evlife::io {
namespace {

constexpr auto kTimeout = std::chrono::seconds(10);
// A forked child inherits libhdf5's global lock (a thread-safe build's, as
// Debian's) in whatever state it was: held by another thread of the parent
// (a second reader opening a file, h5py), it is never released in the child.
// The child says it got past the lock; one that does not within this time
// is stuck on it, not on the file, and is forked again a little later.
constexpr int kLockWaitMs = 300;
constexpr int kForks = 4;
constexpr int kBackoffMs[kForks] = {0, 20, 100, 500};

// In the child: the reader's opening calls, on every dataset it may open.
[[noreturn]] void probe(const char* path, int ready_fd) {
  // Die by the signal itself: a crash handler inherited from the parent (a
  // sanitizer's, a fuzzer's) would report the child's crash as the
  // parent's, while the parent turns it into a ReadError.
  for (const int sig : {SIGFPE, SIGSEGV, SIGBUS, SIGILL, SIGABRT}) signal(sig, SIG_DFL);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // an API call: it takes the library's lock
  const char ready = 1;
  if (write(ready_fd, &ready, 1) != 1) _exit(0);  // the parent is gone
  close(ready_fd);
  const hid_t file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
  if (file >= 0) {
    for (const char* name : {"width", "height"}) (void)read_int_attribute(file, name);  // the reader's lookups
    for (const char* name : {"events/x", "events/y", "events/t", "events/p", "t_offset",
                             "CD/events", "x", "y", "t", "p"}) {
      const hid_t dataset = H5Dopen2(file, name, H5P_DEFAULT);
      if (dataset < 0) continue;
      const hid_t space = H5Dget_space(dataset);
      const hid_t type = H5Dget_type(dataset);
      (void)read_string_attribute(dataset, "units");  // a time column's (a corrupt one hung in libhdf5)
      const hid_t properties = H5Dget_create_plist(dataset);
      if (properties >= 0) H5Pclose(properties);
      if (type >= 0) H5Tclose(type);
      if (space >= 0) H5Sclose(space);
      H5Dclose(dataset);
    }
    H5Fclose(file);
  }
  _exit(0);  // no atexit handlers, no flushing of the parent's stdio buffers
}

/// Whether the child wrote its byte within `ms` (false: stuck on the lock).
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

bool probe_in_child(const std::string& path);

}  // namespace

void probe_hdf5_open_in_child(const std::string& path) {
  // A command opens a file more than once (its format, its sensor, its
  // events): the verdict on the same unchanged file is kept for a minute, so
  // that a hanging one costs the timeout once. The same file: device, inode,
  // size, modification and change times (a copy that keeps the modification
  // time, cp -p, has another inode or change time); for a minute: a Python
  // session or a Dask worker probes a file again later (a verdict of a
  // loaded machine's timeout is not kept for good).
  struct FileKey {
    dev_t device = 0;
    ino_t inode = 0;
    off_t size = 0;
    timespec modified{}, changed{};
    bool operator==(const FileKey& o) const noexcept {
      return device == o.device && inode == o.inode && size == o.size && modified.tv_sec == o.modified.tv_sec &&
             modified.tv_nsec == o.modified.tv_nsec && changed.tv_sec == o.changed.tv_sec &&
             changed.tv_nsec == o.changed.tv_nsec;
    }
  };
  struct Verdict {
    std::string path;
    FileKey key;
    std::chrono::steady_clock::time_point until;
    std::optional<ReadError> fault;
  };
  static std::mutex mutex;
  static std::optional<Verdict> last;
  struct stat st {};
  const bool known = ::stat(path.c_str(), &st) == 0;
  const FileKey key{st.st_dev, st.st_ino, st.st_size, st.st_mtim, st.st_ctim};
  if (known) {
    const std::lock_guard lock(mutex);
    if (last && last->path == path && last->key == key && std::chrono::steady_clock::now() < last->until) {
      if (last->fault) throw *last->fault;
      return;
    }
  }
  std::optional<ReadError> fault;
  bool probed = false;
  try {
    probed = probe_in_child(path);
  } catch (const ReadError& e) {
    fault = e;
    probed = true;
  }
  if (known && probed) {  // (not probed: every child stuck on the library's lock; try again next time)
    const std::lock_guard lock(mutex);
    last = Verdict{path, key, std::chrono::steady_clock::now() + std::chrono::minutes(1), fault};
  }
  if (fault) throw *fault;
}

namespace {

// True when a child probed the file (and found nothing); false when none
// could (no fork, no pipe, every child stuck on the library's lock).
bool probe_in_child(const std::string& path) {
  pid_t child = -1;
  for (int attempt = 0; attempt < kForks && child < 0; ++attempt) {
    std::this_thread::sleep_for(std::chrono::milliseconds(kBackoffMs[attempt]));
    int ready[2];
    if (pipe(ready) != 0) return false;  // cannot: go on without the probe
    const pid_t forked = fork();
    if (forked < 0) {  // cannot fork: go on without the probe
      close(ready[0]);
      close(ready[1]);
      return false;
    }
    if (forked == 0) {
      close(ready[0]);
      probe(path.c_str(), ready[1]);
    }
    close(ready[1]);
    const bool ready_in_time = child_ready(ready[0], kLockWaitMs);
    close(ready[0]);
    if (ready_in_time || waitpid(forked, nullptr, WNOHANG) == forked) {
      child = forked;  // past the lock (or already ended: its status below)
    } else {
      kill(forked, SIGKILL);
      waitpid(forked, nullptr, 0);
    }
  }
  // Every child stuck on the lock (another thread kept the library busy):
  // go on without the probe, as without fork().
  if (child < 0) return false;
  const auto deadline = std::chrono::steady_clock::now() + kTimeout;
  int status = 0;
  while (true) {
    const pid_t done = waitpid(child, &status, WNOHANG);
    if (done == child) break;
    if (done < 0) return false;
    if (std::chrono::steady_clock::now() > deadline) {
      kill(child, SIGKILL);
      waitpid(child, &status, 0);
      throw ReadError(path, -1, -1, "the HDF5 library hangs opening this file (corrupt HDF5?)");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  if (WIFSIGNALED(status)) {
    throw ReadError(path, -1, -1,
                    std::string("the HDF5 library crashes opening this file (signal ") +
                        std::to_string(WTERMSIG(status)) + ", " + strsignal(WTERMSIG(status)) +
                        "): corrupt HDF5");
  }
  // The child exits 0 unless something killed it in its own way (e.g. a
  // sanitizer's report of the same crash): as bad as a signal.
  if (WIFEXITED(status) && WEXITSTATUS(status) != 0) {
    throw ReadError(path, -1, -1,
                    "the HDF5 library fails hard opening this file (probe exit status " +
                        std::to_string(WEXITSTATUS(status)) + "): corrupt HDF5");
  }
  return true;
}

}  // namespace

}  // namespace evlife::io
