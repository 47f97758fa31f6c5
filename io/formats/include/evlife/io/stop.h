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

/// A stop that only the calling thread can see (Python's Ctrl-C: its
/// signal is seen by the interpreter's main thread alone): stop_requested()
/// on this thread also asks `check(context)`. nullptr: none.
using ThreadStopCheck = bool (*)(void* context) noexcept;
void set_thread_stop_check(ThreadStopCheck check, void* context) noexcept;

/// True once a stop flag is set and true, or this thread's check says so.
bool stop_requested() noexcept;

}  // namespace evlife::io
