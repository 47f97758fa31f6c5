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
#include <string>

#include "evlife/io/event_reader.h"

namespace evlife::python {

namespace py = pybind11;

/// Sets the Python error for `e` and throws py::error_already_set. `partial`
/// is attached to an InputError. Needs the GIL.
[[noreturn]] void raise_input_error(const io::ReadError& e, py::object partial = py::none());

/// Ctrl-C during a long call that runs without the GIL: pending(), called
/// between blocks of events, asks Python at most every 100 ms whether a
/// signal handler raised (SIGINT's: KeyboardInterrupt). Construct and
/// destroy it with the GIL held; pending() runs without it.
class SignalCheck {
 public:
  bool pending();
  /// With the GIL, at the end of the call: pending() now, without its 100 ms
  /// wait (a Ctrl-C during the last block is said with the whole result).
  bool pending_now();
  /// With the GIL, after pending(): raises evlife.Interrupted (a
  /// KeyboardInterrupt) with `message` and the attributes partial,
  /// events_processed and events_written; or what the handler raised if it
  /// raised something else.
  [[noreturn]] void raise(const std::string& message, py::object partial, std::uint64_t events_processed,
                          py::object events_written);

 private:
  bool fetch();  // with the GIL: runs Python's signal handlers, keeps what they raised
  std::chrono::steady_clock::time_point next_check_{};
  py::object type_, value_, traceback_;  // the handler's exception, once raised
};

void bind_errors(py::module_& m);

}  // namespace evlife::python
