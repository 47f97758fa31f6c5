// A stop (the command line's Ctrl-C, kill, hang-up) that the io calls which
// can wait or work for long heed, where no loop of the caller's runs between:
// - a write to a FIFO whose reader takes no data blocks for ever, and a
//   command stopped by Ctrl-C waited with it (the signal lands on another
//   thread, and SA_RESTART restarts the call): the writers' FIFOs are written
//   without blocking, and while the reader takes nothing they wait for room
//   in steps of 100 ms; once the flag is true they fail with a WriteError
//   saying so (the bytes not written counted);
// - the decompression of a file-compressed ROS 2 bag (NAME.db3.zstd) into its
//   temporary copy, seconds for gigabytes, when the bag is opened: once the
//   flag is true it fails with a ReadError saying so (the copy removed).
#pragma once

#include <atomic>

namespace evlife::io {

/// The flag (nullptr: none; e.g. the command line's stop flag, set by its
/// signal handlers) for the whole process.
void set_stop_flag(const std::atomic<bool>* flag) noexcept;

/// True once a stop flag is set and true.
bool stop_requested() noexcept;

}  // namespace evlife::io
