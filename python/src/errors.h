// C++ errors as Python exceptions, with the command line's messages:
//   io::ReadError      -> evlife.InputError (a ValueError) with .path,
//                         .byte_offset, .event_index and .partial (the good
//                         events before the fault, or None); FileNotFoundError
//                         for a missing file
//   config::ConfigError, std::invalid_argument -> ValueError
//   io::WriteError     -> OSError
#pragma once

#include <pybind11/pybind11.h>

#include "evlife/io/event_reader.h"

namespace evlife::python {

namespace py = pybind11;

/// Sets the Python error for `e` and throws py::error_already_set. `partial`
/// is attached to an InputError. Needs the GIL.
[[noreturn]] void raise_input_error(const io::ReadError& e, py::object partial = py::none());

void bind_errors(py::module_& m);

}  // namespace evlife::python
