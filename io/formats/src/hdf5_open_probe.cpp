#include "hdf5_open_probe.h"

#include <hdf5.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "evlife/io/event_reader.h"
#include "hdf5_attributes.h"
#include "hdf5_child.h"
#include "hdf5_signature.h"

namespace evlife::io {
namespace {

constexpr auto kTimeout = std::chrono::seconds(10);
// The probe's exit status when libhdf5 refuses to open the file: the parent
// then never calls H5Fopen on it itself (a failed open left libhdf5's state
// half built: "HDF5: infinite loop closing library" and a line of its free
// lists at the process's exit, after the error). Not kept as the file's
// verdict: a file locked by its writer opens once the lock is gone.
constexpr int kCannotOpenExit = 3;
constexpr int kLockedExit = 4;  // refused for HDF5's file lock: another process writes it

herr_t find_lock_error(unsigned /*n*/, const H5E_error2_t* error, void* found) {
  if (error->min_num == H5E_CANTLOCKFILE) *static_cast<bool*>(found) = true;
  return 0;
}

constexpr unsigned kOrphanCheckS = 5;  // how often the probe asks whether its parent still waits for it
pid_t probe_parent = 0;

// The parent kills a probe that hangs (past kTimeout, not waiting for the
// disk); one whose parent died first ends here. Not a plain alarm ending the
// probe: a parent still waiting for a probe on slow storage keeps it alive.
void end_if_orphaned(int /*signal*/) {
  if (getppid() != probe_parent) _exit(kCannotOpenExit);
  alarm(kOrphanCheckS);
}

// In the child: the reader's opening calls, on every dataset it may open.
void probe(void* context) {
  const char* path = static_cast<const char*>(context);
  probe_parent = getppid();
  struct sigaction orphan_check {};
  orphan_check.sa_handler = &end_if_orphaned;
  orphan_check.sa_flags = SA_RESTART;  // libhdf5's reads go on after the check
  sigaction(SIGALRM, &orphan_check, nullptr);
  alarm(kOrphanCheckS);
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
    _exit(0);
  }
  bool locked = false;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_DOWNWARD, &find_lock_error, &locked);
  _exit(locked ? kLockedExit : kCannotOpenExit);
}

bool probe_in_child(const std::string& path);

// A refusal that says nothing lasting of the file (its open failed now: a
// lock): not kept as its verdict.
struct UnkeptOpenFault : ReadError {
  using ReadError::ReadError;
};

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
  } catch (const UnkeptOpenFault& e) {
    throw ReadError(e);  // asked again next time
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
  const pid_t child = detail::fork_hdf5_child(&probe, const_cast<char*>(path.c_str()));
  // No child (no fork, or every child stuck on the library's lock, another
  // thread keeping it busy): go on without the probe.
  if (child < 0) return false;
  auto deadline = std::chrono::steady_clock::now() + kTimeout;
  int status = 0;
  auto last = std::chrono::steady_clock::now();
  while (true) {
    const pid_t done = waitpid(child, &status, WNOHANG);
    if (done == child) break;
    if (done < 0) return false;
    // A step far longer than its 1 ms: this process was stopped (Ctrl-Z); not the probe's time.
    const auto now = std::chrono::steady_clock::now();
    if (now - last > std::chrono::seconds(1)) deadline += now - last;
    last = now;
    if (now > deadline && detail::waits_for_disk(child)) deadline = now + kTimeout;  // slow storage, still opening
    if (now > deadline) {
      kill(child, SIGKILL);
      waitpid(child, &status, 0);
      throw ReadError(path, -1, -1,
                      "the HDF5 library hangs opening this file (corrupt HDF5? no answer in " +
                          std::to_string(std::chrono::duration_cast<std::chrono::seconds>(kTimeout).count()) +
                          " s)");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == kLockedExit)
    throw UnkeptOpenFault(path, -1, -1,
                          "HDF5 library cannot open the file: another process holds its lock (writing it?); "
                          "HDF5_USE_FILE_LOCKING=FALSE reads it anyway");
  if (WIFEXITED(status) && WEXITSTATUS(status) == kCannotOpenExit)
    throw UnkeptOpenFault(path, -1, -1, hdf5_cannot_open_reason(path));
  // A probe killed from outside (the OOM killer: a corrupt file can make
  // libhdf5 ask for any size) says nothing of the file: refused all the
  // same, never opened unprobed.
  if (const auto fault = detail::hdf5_child_fault(status); !fault.verb.empty())
    throw ReadError(path, -1, -1, "the HDF5 library " + fault.verb + " opening this file " + fault.detail +
                                      (fault.corrupt ? ": corrupt HDF5" : ""));
  return true;
}

}  // namespace

namespace detail {

std::optional<std::uint64_t> hdf5_stated_end(std::span<const std::uint8_t> head) noexcept {
  if (!starts_with_hdf5_signature(head.data(), head.size()) || head.size() < 16) return std::nullopt;
  const std::uint8_t version = head[8];
  // (HDF5 file format specification, "Superblock": the offsets' size, then
  // where the base address stands; the end-of-file address two offsets after it.)
  const std::size_t offset_bytes = version <= 1 ? head[13] : head[9];
  const std::size_t base_at = version == 0 ? 24 : version == 1 ? 28 : 12;
  if (version > 3 || (offset_bytes != 2 && offset_bytes != 4 && offset_bytes != 8)) return std::nullopt;
  const auto address = [&](std::size_t at) -> std::optional<std::uint64_t> {
    if (at + offset_bytes > head.size()) return std::nullopt;
    std::uint64_t v = 0;
    for (std::size_t k = 0; k < offset_bytes; ++k) v |= std::uint64_t{head[at + k]} << (8 * k);  // little-endian
    if (offset_bytes < 8 ? v == (std::uint64_t{1} << (8 * offset_bytes)) - 1 : v == UINT64_MAX) return std::nullopt;
    return v;  // (all ones: the undefined address)
  };
  const auto base = address(base_at), end = address(base_at + 2 * offset_bytes);
  if (!base || !end || *end > UINT64_MAX - *base) return std::nullopt;
  return *base + *end;
}

}  // namespace detail

std::string hdf5_cannot_open_reason(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::array<std::uint8_t, 64> head{};
  in.read(reinterpret_cast<char*>(head.data()), static_cast<std::streamsize>(head.size()));
  const auto got = static_cast<std::size_t>(std::max<std::streamsize>(in.gcount(), 0));
  std::error_code ec;
  const std::uint64_t size = std::filesystem::file_size(path, ec);
  const auto stated = detail::hdf5_stated_end(std::span(head.data(), got));
  if (ec || !stated || size >= *stated) return kHdf5CannotOpen;
  return std::string(kHdf5CannotOpen) + "; cut: the file has " + std::to_string(size) +
         " bytes where its superblock states " + std::to_string(*stated) + " (a copy or download that stopped short?)";
}

}  // namespace evlife::io
