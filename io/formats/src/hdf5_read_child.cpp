#include "hdf5_read_child.h"

#include <dirent.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace evlife::io::detail {
namespace {

// No answer at all in this time: the child hangs in libhdf5 (a corrupt file
// can loop it). Generous: a read of a 256 MiB chunk (the largest the reader
// opens) from a slow card takes seconds.
constexpr auto kAnswerTimeout = std::chrono::seconds(60);
constexpr int kPollSliceMs = 100;  // between checks that the child still runs

struct Request {
  std::int64_t dataset;
  std::int64_t first;
  std::uint64_t count;
  std::uint64_t bytes;        // of the values, <= kSharedBytes
  std::uint64_t type_bytes;   // of the memory type, encoded (H5Tencode), after this
  std::int32_t columns;
  std::int32_t column;
  std::int32_t whole;
};
static_assert(sizeof(hid_t) == sizeof(std::int64_t));
// The answer (one byte); with kRead, the values are in the shared region.
constexpr unsigned char kFailed = 0, kRead = 1, kUnknownDataset = 2;
// The region shared with the child, which libhdf5 reads the values into:
// no copy through the socket. Holds a reader's largest read (an N×4 table's
// chunk as doubles, 2 MiB); larger ones are read in pieces of rows.
constexpr std::size_t kSharedBytes = std::size_t{4} << 20;

bool write_all(int fd, const void* data, std::size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  while (bytes > 0) {
    const ssize_t n = send(fd, p, bytes, MSG_NOSIGNAL);  // a gone peer: an error, not SIGPIPE
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    bytes -= static_cast<std::size_t>(n);
  }
  return true;
}

bool read_all(int fd, void* data, std::size_t bytes) {
  auto* p = static_cast<unsigned char*>(data);
  while (bytes > 0) {
    const ssize_t n = recv(fd, p, bytes, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    bytes -= static_cast<std::size_t>(n);
  }
  return true;
}

H5T_conv_ret_t refuse_lossy_conversion(H5T_conv_except_t kind, hid_t, hid_t, void*, void*, void*) {
  return kind == H5T_CONV_EXCEPT_PRECISION ? H5T_CONV_UNHANDLED : H5T_CONV_ABORT;  // int64 -> double
}

struct ChildContext {
  int socket;  // the child's end
  pid_t parent;
  unsigned char* values;  // the shared region the child reads into
};

// Closes the parent's descriptors that the child must not hold: pipes and
// sockets (their other ends would wait for an end of file as long as the
// reader lives: a pipe to `wc`, another reader's socket to its child) and
// files open for writing (the command's outputs, their locks). Kept: 0-2 (a
// sanitizer's report), the child's socket, and files open read-only, which
// libhdf5 reads (the reader's file, files its external links opened, a
// driver's several files).
void close_inherited_descriptors(int socket) {
  DIR* dir = opendir("/proc/self/fd");
  if (dir == nullptr) return;  // (no /proc: none closed)
  std::vector<int> fds;
  while (const dirent* entry = readdir(dir)) {
    char* end = nullptr;
    const long fd = std::strtol(entry->d_name, &end, 10);
    if (*end == '\0' && end != entry->d_name && fd > 2 && fd != socket && fd != dirfd(dir)) fds.push_back(static_cast<int>(fd));
  }
  closedir(dir);
  for (const int fd : fds) {
    struct stat st {};
    const int flags = fcntl(fd, F_GETFL);
    if (flags >= 0 && (flags & O_ACCMODE) == O_RDONLY && fstat(fd, &st) == 0 && S_ISREG(st.st_mode)) continue;
    close(fd);
  }
}

// Whether a request came (false: the parent ended or closed its end).
bool wait_for_request(const ChildContext& c) {
  for (;;) {
    pollfd fd{c.socket, POLLIN, 0};
    const int polled = poll(&fd, 1, 1000);
    if (polled > 0) return true;
    if (polled < 0 && errno != EINTR) return false;
    if (getppid() != c.parent) return false;  // adopted: the parent is gone
  }
}

// In the child: answers requests until the parent closes its end or ends.
void serve(void* context) {
  // (No PR_SET_PDEATHSIG: it follows the forking thread, which may end
  // before the reader. Its socket's end closing, or being adopted, ends it.)
  const auto& c = *static_cast<const ChildContext*>(context);
  close_inherited_descriptors(c.socket);
  std::vector<unsigned char> type_code;
  for (;;) {
    Request r{};
    if (!wait_for_request(c) || !read_all(c.socket, &r, sizeof r)) _exit(0);
    type_code.resize(r.type_bytes);
    if (!read_all(c.socket, type_code.data(), type_code.size())) _exit(0);
    const hid_t type = H5Tdecode(type_code.data());
    const hid_t dataset = r.dataset;
    // Only handles inherited from the parent are read (the child opens no
    // dataset): one the parent opened since the fork is unknown here.
    const bool known = H5Iget_type(dataset) == H5I_DATASET;
    const bool ok = known && type >= 0 && r.bytes <= kSharedBytes &&
                    read_selection(dataset, type,
                                   Hdf5Selection{r.first, r.count, r.columns, r.column, r.whole != 0}, c.values);
    if (type >= 0) H5Tclose(type);
    const unsigned char status = ok ? kRead : known ? kFailed : kUnknownDataset;
    if (!write_all(c.socket, &status, 1)) _exit(0);
  }
}

// EVLIFE_HDF5_IN_PROCESS=1: the reads in the process, no child (memory).
bool reads_in_process_by_choice() {
  const char* value = std::getenv("EVLIFE_HDF5_IN_PROCESS");
  return value != nullptr && std::strcmp(value, "1") == 0;
}


}  // namespace

std::uint64_t selection_bytes(hid_t dataset, hid_t memory_type, const Hdf5Selection& selection) {
  const std::size_t value = H5Tget_size(memory_type);
  if (value == 0) return 0;
  if (!selection.whole) {
    const std::uint64_t per_row = selection.columns > 0 && selection.column < 0 ? selection.columns : 1;
    return selection.count * per_row * value;
  }
  const hid_t space = H5Dget_space(dataset);
  if (space < 0) return 0;
  const hssize_t points = H5Sget_simple_extent_npoints(space);
  H5Sclose(space);
  return points > 0 ? static_cast<std::uint64_t>(points) * value : 0;
}

bool read_selection(hid_t dataset, hid_t memory_type, const Hdf5Selection& selection, void* out) {
  const hid_t transfer = H5Pcreate(H5P_DATASET_XFER);
  if (transfer < 0) return false;
  bool ok = H5Pset_type_conv_cb(transfer, refuse_lossy_conversion, nullptr) >= 0;
  if (ok && selection.whole) {
    ok = H5Dread(dataset, memory_type, H5S_ALL, H5S_ALL, transfer, out) >= 0;
  } else if (ok) {
    const hid_t file_space = H5Dget_space(dataset);
    const int rank = selection.columns > 0 ? 2 : 1;
    const hsize_t start[2] = {static_cast<hsize_t>(selection.first),
                              static_cast<hsize_t>(std::max(selection.column, 0))};
    const hsize_t size[2] = {selection.count,
                             static_cast<hsize_t>(selection.column >= 0 ? 1 : selection.columns)};
    const hid_t memory_space = H5Screate_simple(rank, size, nullptr);
    ok = file_space >= 0 && memory_space >= 0 &&
         H5Sselect_hyperslab(file_space, H5S_SELECT_SET, start, nullptr, size, nullptr) >= 0 &&
         H5Dread(dataset, memory_type, memory_space, file_space, transfer, out) >= 0;
    if (memory_space >= 0) H5Sclose(memory_space);
    if (file_space >= 0) H5Sclose(file_space);
  }
  H5Pclose(transfer);
  return ok;
}

bool Hdf5ReadChild::read(hid_t dataset, hid_t memory_type, const Hdf5Selection& selection, void* out,
                         std::size_t out_bytes) {
  if (fault_) return false;
  if (owner_ != getpid()) forget_after_fork();
  const std::uint64_t bytes = selection_bytes(dataset, memory_type, selection);
  if (bytes == 0 || bytes > out_bytes) return selection.count == 0 && !selection.whole;  // nothing to read
  if (child_ < 0 && !in_process_ && (reads_in_process_by_choice() || !start())) in_process_ = true;
  if (in_process_) return read_selection(dataset, memory_type, selection, out);
  if (bytes > kSharedBytes) {  // in pieces of rows that fit the region (a whole dataset cannot be cut)
    if (selection.whole) return false;
    const std::uint64_t row_bytes = bytes / selection.count;
    const std::uint64_t rows = kSharedBytes / row_bytes;
    auto* to = static_cast<unsigned char*>(out);
    for (std::uint64_t done = 0; done < selection.count; done += rows) {
      Hdf5Selection piece = selection;
      piece.first += static_cast<std::int64_t>(done);
      piece.count = std::min(rows, selection.count - done);
      if (!read(dataset, memory_type, piece, to + done * row_bytes, piece.count * row_bytes)) return false;
    }
    return true;
  }
  std::size_t type_bytes = 0;
  if (H5Tencode(memory_type, nullptr, &type_bytes) < 0) return false;
  request_.resize(sizeof(Request) + type_bytes);
  const Request r{dataset, selection.first, selection.count, bytes, type_bytes, selection.columns, selection.column,
                  selection.whole ? 1 : 0};
  std::memcpy(request_.data(), &r, sizeof r);
  if (H5Tencode(memory_type, request_.data() + sizeof r, &type_bytes) < 0) return false;
  int answer = exchange(request_.data(), request_.size());
  if (answer == kUnknownDataset) {  // opened since the child was forked: a child that knows it
    stop();
    if (!start()) {
      in_process_ = true;
      return read_selection(dataset, memory_type, selection, out);
    }
    answer = exchange(request_.data(), request_.size());
  }
  if (answer != kRead) return false;
  std::memcpy(out, shared_, bytes);
  return true;
}

int Hdf5ReadChild::exchange(const void* request, std::size_t request_bytes) {
  if (!write_all(socket_, request, request_bytes)) {  // the child ended
    int status = 0;
    child_ended(waitpid(child_, &status, 0) == child_ ? status : 0);
    return kFailed;
  }
  unsigned char answer = kFailed;
  return receive_answer(answer) ? answer : kFailed;
}

bool Hdf5ReadChild::receive_answer(unsigned char& answer) {
  auto deadline = std::chrono::steady_clock::now() + kAnswerTimeout;
  for (;;) {
    pollfd fd{socket_, POLLIN, 0};
    const auto before = std::chrono::steady_clock::now();
    const int polled = poll(&fd, 1, kPollSliceMs);
    // A slice that took far longer than asked: this process was stopped
    // (Ctrl-Z) or starved, not waiting on the child; that time is not the child's.
    if (const auto slept = std::chrono::steady_clock::now() - before; slept > 10 * std::chrono::milliseconds(kPollSliceMs))
      deadline += slept;
    if (polled > 0) {
      const ssize_t n = recv(socket_, &answer, 1, 0);
      if (n == 1) return true;
      if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    } else if (polled < 0 && errno == EINTR) {
      continue;
    }
    // An end of the socket (the child ending), an error, or a slice without
    // an answer: has the child ended?
    int status = 0;
    const pid_t done = waitpid(child_, &status, polled == 0 ? WNOHANG : 0);
    if (done == child_ || (done < 0 && errno == ECHILD)) {
      child_ended(done == child_ ? status : 0);
      return false;
    }
    if (polled == 0 && std::chrono::steady_clock::now() > deadline && detail::waits_for_disk(child_)) {
      deadline = std::chrono::steady_clock::now() + kAnswerTimeout;  // slow storage, still reading
      continue;
    }
    if (polled != 0 || std::chrono::steady_clock::now() > deadline) {
      kill(child_, SIGKILL);
      waitpid(child_, nullptr, 0);
      child_ = -1;
      fault_ = Hdf5ChildFault{"hangs", "(no answer in " + std::to_string(kAnswerTimeout.count()) + " s)", true};
      stop();
      return false;
    }
  }
}

void Hdf5ReadChild::child_ended(int wait_status) {
  child_ = -1;
  auto fault = hdf5_child_fault(wait_status);
  if (fault.verb.empty()) fault = {"ends", "(its reading process ended)", false};
  fault_ = fault;
  stop();
}

bool Hdf5ReadChild::start() {
  int pair[2];
  if (socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, pair) != 0) return false;
  if (shared_ == nullptr) {
    void* region = mmap(nullptr, kSharedBytes, PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
    if (region == MAP_FAILED) {
      close(pair[0]);
      close(pair[1]);
      return false;
    }
    shared_ = static_cast<unsigned char*>(region);
  }
  ChildContext context{pair[1], getpid(), shared_};
  const pid_t child = fork_hdf5_child(&serve, &context);
  close(pair[1]);
  if (child < 0) {
    close(pair[0]);
    return false;
  }
  socket_ = pair[0];
  child_ = child;
  owner_ = getpid();
  return true;
}

// In a copy of the process made by fork() (Python's os.fork, a
// multiprocessing pool): the child and the shared region are the original
// process's. Killing that child, or asking it, would break the original's
// reading (its answers read by either process): this copy lets go of them
// and forks its own child at its next read.
void Hdf5ReadChild::forget_after_fork() noexcept {
  if (socket_ >= 0) close(socket_);  // this process's copy of the original's end
  if (shared_ != nullptr) munmap(shared_, kSharedBytes);  // this process's view only
  socket_ = -1;
  child_ = -1;
  shared_ = nullptr;
  owner_ = getpid();
}

void Hdf5ReadChild::stop() noexcept {
  if (owner_ != getpid()) forget_after_fork();
  if (child_ > 0) {
    kill(child_, SIGKILL);  // idle, waiting for a request: nothing of it to keep
    waitpid(child_, nullptr, 0);
    child_ = -1;
  }
  if (socket_ >= 0) close(socket_);
  socket_ = -1;
}

Hdf5ReadChild::~Hdf5ReadChild() {
  stop();  // (in a forked copy: forgets the original's child and region)
  if (shared_ != nullptr) munmap(shared_, kSharedBytes);
}

}  // namespace evlife::io::detail
