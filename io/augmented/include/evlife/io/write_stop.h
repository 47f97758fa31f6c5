// A stop that writes to a FIFO heed. A write to a FIFO whose reader takes no
// data blocks for ever, and a command stopped by Ctrl-C waited with it (the
// signal lands on another thread, and SA_RESTART restarts the call): the
// writers' FIFOs are written without blocking, and while the reader takes
// nothing they wait for room in steps of 100 ms; once the flag given here is
// true they fail with a WriteError saying so (the bytes not written counted).
#pragma once

#include <atomic>

namespace evlife::io {

/// The flag (nullptr: none; e.g. the command line's stop flag, set by its
/// signal handlers) for the whole process.
void set_write_stop_flag(const std::atomic<bool>* flag) noexcept;

/// True once a stop flag is set and true.
bool write_stop_requested() noexcept;

}  // namespace evlife::io
