// C++ errors as Python exceptions, with the command line's messages:
//   io::ReadError      -> evlife.InputError (a ValueError) with .path,
//                         .byte_offset, .event_index and .partial (the good
//                         events before the fault, or None); FileNotFoundError
//                         for a missing file
//   config::ConfigError, std::invalid_argument -> ValueError
//   io::WriteError     -> OSError
// and Ctrl-C during a long call (SignalCheck) -> evlife.Interrupted (a
// KeyboardInterrupt) with what was done.
#pragma once

#include <pybind11/pybind11.h>

#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

#include "bindings.h"  // ReleasedGil
#include "evlife/io/event_reader.h"

namespace evlife::python {

namespace py = pybind11;

/// Sets the Python error for `e` and throws py::error_already_set. `partial`
/// is attached to an InputError. Needs the GIL.
[[noreturn]] void raise_input_error(const io::ReadError& e, py::object partial = py::none());

/// Ctrl-C during a long call that runs without the GIL: pending(), called
/// between blocks of events, asks Python at most every 100 ms whether SIGINT
/// came (PyOS_InterruptOccurred: no handler runs inside the call, which holds
/// the estimator's lock). Only on the main thread (the one Python's handlers
/// run on; another may be a daemon at the interpreter's exit) and while
/// SIGINT's handler is Python's default (KeyboardInterrupt): a handler of the
/// user's runs after the call, as before. Construct it with the GIL held;
/// pending() runs without it.
class SignalCheck {
 public:
  /// `long_call` false (a call of one block): never checks (no cost).
  explicit SignalCheck(bool long_call = true);
  bool pending();
  /// With the GIL, at the end of the call: pending() now, without its 100 ms
  /// wait (a Ctrl-C during the last block is said with the whole result).
  bool pending_now();
  /// With the GIL, after pending(): raises evlife.Interrupted (a
  /// KeyboardInterrupt) with `message` and the attributes partial,
  /// events_processed and events_written.
  [[noreturn]] static void raise(const std::string& message, py::object partial, std::uint64_t events_processed,
                                 py::object events_written);

 private:
  bool enabled_ = false;
  bool interrupted_ = false;
  std::chrono::steady_clock::time_point next_check_{};
};

/// While it lives, io::stop_requested() on this thread asks `signals`: the
/// io calls that wait or work long without a loop of ours between (a FIFO
/// output no reader opens or drains, a NAME.db3.zstd decompressed at its
/// opening) stop on Ctrl-C with their error, which the call raises as
/// evlife.Interrupted where signals.pending() is then true. Construct it on
/// the thread that runs those calls (not a write-behind thread's: its waits
/// hear nothing), with `signals` outliving it; scopes do not nest.
class IoStopScope {
 public:
  explicit IoStopScope(SignalCheck& signals) noexcept;
  ~IoStopScope();
  IoStopScope(const IoStopScope&) = delete;
  IoStopScope& operator=(const IoStopScope&) = delete;
};

/// Runs f() holding `mutex` (an object's lock that another Python thread's
/// long call may hold: an estimator's process, a reader's read), the GIL
/// released; waits in steps of 20 ms, so that Ctrl-C on the main thread ends
/// the wait: then false, f not run (raise_interrupted_while_waiting()). Call
/// it with the GIL.
template <class F>
[[nodiscard]] bool run_locked_unless_interrupted(std::timed_mutex& mutex, F&& f) {
  SignalCheck waiting;
  const ReleasedGil release;
  std::unique_lock lock(mutex, std::defer_lock);
  while (!lock.try_lock_for(std::chrono::milliseconds(20))) {
    if (waiting.pending()) return false;
  }
  f();
  return true;
}

/// evlife.Interrupted "`who`: interrupted while another thread's call held
/// `object`; `nothing`" (run_locked_unless_interrupted() returned false),
/// with `partial` and no event processed.
[[noreturn]] void raise_interrupted_while_waiting(const std::string& who, const char* object, const char* nothing,
                                                  py::object partial = py::none());

/// A RuntimeWarning with `text`, attributed to the user's line: the caller of
/// the Python wrapper every public reading function has (_streams.py); the
/// copy of a named pipe this thread reads (_stream_alias) is named as the
/// pipe. An exception where warnings are errors (py::error_already_set).
/// Needs the GIL. `stacklevel` as warnings.warn's: 1 for a method the user
/// calls directly (evlife.Reader's, which have no wrapper).
void warn_at_callers_line(std::string text, int stacklevel = 2);

void bind_errors(py::module_& m);

}  // namespace evlife::python
