// libhdf5 1.10 (Debian 12) can crash the process on some corrupt files while
// merely opening a dataset (e.g. SIGFPE for a chunk dimension of 0, found by
// fuzzing: tests/fuzz/regressions/hdf5/). The probe repeats the reader's
// opening steps in a forked child first (hdf5_child.h), so that such a crash
// becomes a ReadError in the caller instead of killing it; the reads that
// follow are done by another child (hdf5_read_child.h).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include <string>

namespace evlife::io {

/// Opens `path`, its sensor attributes and the event datasets of every known
/// layout with their units attributes in a child process. Throws ReadError if
/// the child dies of a signal, exits non-zero (a sanitizer's report) or hangs
/// on the file (> 10 s), or libhdf5 will not open it (kHdf5CannotOpen, or
/// another process's file lock: then this process never calls H5Fopen on it);
/// returns normally otherwise (errors the library reports past the open are
/// left to the reader, which names them). The verdict on a file is kept for
/// a minute while it is the same file, unchanged (device, inode, size,
/// modification and change times): a command opening it again (format,
/// sensor, events) waits out a hang once. A refused open is not kept: a lock
/// goes away.
void probe_hdf5_open_in_child(const std::string& path);

/// The refusal of a file libhdf5 will not open (the probe's child's verdict,
/// or the reader's own H5Fopen where no child could be forked).
inline constexpr const char* kHdf5CannotOpen = "HDF5 library cannot open the file (corrupt?)";

/// kHdf5CannotOpen, and where the file is shorter than its superblock states
/// (hdf5_stated_end), what the cut left: "cut: the file has N bytes where its
/// superblock states M" (a copy or download that stopped short; the library
/// says only that it cannot open it).
std::string hdf5_cannot_open_reason(const std::string& path);

namespace detail {
/// Where the superblock at the start of `head` (a file's first bytes) says
/// the file ends: its base address + end-of-file address, for superblock
/// versions 0-3 with 2-, 4- or 8-byte offsets; nothing where it cannot tell.
std::optional<std::uint64_t> hdf5_stated_end(std::span<const std::uint8_t> head) noexcept;
}  // namespace detail

}  // namespace evlife::io
