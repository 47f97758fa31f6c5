// An HDF5 reader's dataset reads done by a forked child process
// (hdf5_child.h). libhdf5 1.10 (Debian 12's) can crash inside H5Dread on a
// corrupt chunk (one byte changed in a deflated chunk: SIGSEGV), where no
// check of ours can reach first; in the child, such a crash ends the reading
// with a ReadError naming the rows, after the events before them, instead of
// killing the process (a convert's output left empty, a Python session gone).
// The child is forked at the first read and reads with the reader's handles,
// inherited; a dataset opened since then makes a new child. Requests and
// answers cross a socket, the values a region of shared memory.
#pragma once

#include <hdf5.h>
#include <sys/types.h>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "hdf5_child.h"

namespace evlife::io::detail {

/// Which values of a dataset: rows [first, first + count) of a 1-D dataset
/// or of an N×`columns` one (column `column` alone when >= 0, else every
/// column), or, with `whole`, every value of a dataset of any shape.
struct Hdf5Selection {
  std::int64_t first = 0;
  std::uint64_t count = 0;
  std::int32_t columns = 0;  // 0: a 1-D dataset
  std::int32_t column = -1;
  bool whole = false;
};

/// Bytes the selection takes as `memory_type`; 0 when unknown.
std::uint64_t selection_bytes(hid_t dataset, hid_t memory_type, const Hdf5Selection& selection);

/// Reads the selection in this process: what the child does for a request.
/// A value the memory type cannot hold without change fails the read
/// (libhdf5 would clamp or truncate it: silently another event).
bool read_selection(hid_t dataset, hid_t memory_type, const Hdf5Selection& selection, void* out);

class Hdf5ReadChild {
 public:
  Hdf5ReadChild() = default;
  ~Hdf5ReadChild();
  Hdf5ReadChild(const Hdf5ReadChild&) = delete;
  Hdf5ReadChild& operator=(const Hdf5ReadChild&) = delete;

  /// The selection as `memory_type` into `out`, which holds `out_bytes`, read
  /// by the child (forked now if there is none; read in this process when
  /// none can be). False when libhdf5 reports an error, the selection does
  /// not fit `out_bytes`, or the child ended or hung: fault() says which.
  bool read(hid_t dataset, hid_t memory_type, const Hdf5Selection& selection, void* out, std::size_t out_bytes);
  /// Ends the child: the next read forks one that knows datasets opened since.
  void stop() noexcept;
  /// Set once the child crashed, failed hard or hung; every read fails after.
  const std::optional<Hdf5ChildFault>& fault() const noexcept { return fault_; }

 private:
  bool start();  // forks the child; false: read in this process
  // The child's answer to one request, kFailed also when it ended or hung.
  int exchange(const void* request, std::size_t request_bytes);
  bool receive_answer(unsigned char& answer);  // false: the child ended or hung (fault_ set)
  void child_ended(int wait_status);
  void forget_after_fork() noexcept;  // in a forked copy of the process that started the child

  int socket_ = -1;
  unsigned char* shared_ = nullptr;  // the region the child reads the values into
  pid_t child_ = -1;
  pid_t owner_ = -1;  // the process that forked child_ and mapped shared_
  bool in_process_ = false;
  std::optional<Hdf5ChildFault> fault_;
  std::vector<unsigned char> request_;
};

}  // namespace evlife::io::detail
