// One function per part of the module, called by module.cpp.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl/filesystem.h>
#include <cxxabi.h>
#include <unistd.h>

#include <filesystem>

#include <optional>
#include <string>
#include <vector>

#include "evlife/io/event_reader.h"

namespace evlife::python {

namespace py = pybind11;

/// The GIL released for a C++ call, as py::gil_scoped_release, but safe in a
/// daemon thread that comes back while the interpreter finalizes (a script's
/// end, a thread pool's worker mid-call): taking the GIL then ends the thread
/// by pthread_exit, whose unwinding through this noexcept destructor called
/// std::terminate (SIGABRT, exit 134). Such a thread waits here for the
/// process's end instead. (Only daemon threads run during finalization.)
class ReleasedGil {
 public:
  ReleasedGil() : state_(PyEval_SaveThread()) {}
  ~ReleasedGil() {
#if PY_VERSION_HEX >= 0x030D0000
    const bool finalizing = Py_IsFinalizing() != 0;
#else
    const bool finalizing = _Py_IsFinalizing() != 0;
#endif
    if (finalizing) wait_for_the_process_end();
    // Finalization can also begin while this thread waits for the GIL (the
    // main thread holds it until it finalizes): the thread's exit is then a
    // forced unwind from inside the wait, caught here so that it never
    // leaves this noexcept destructor (1 run in ~60 aborted with the check
    // above alone).
    try {
      PyEval_RestoreThread(state_);
    } catch (abi::__forced_unwind&) {
      wait_for_the_process_end();
    }
  }
  ReleasedGil(const ReleasedGil&) = delete;
  ReleasedGil& operator=(const ReleasedGil&) = delete;

 private:
  // Never returns (nor rethrows a caught forced unwind: the thread ends with the process).
  [[noreturn]] static void wait_for_the_process_end() {
    for (;;) pause();
  }

  PyThreadState* state_;
};

void bind_reader(py::module_& m);     // read, open, Reader, read_augmented, write
void bind_estimator(py::module_& m);  // LifetimeEstimator, process
void bind_frame(py::module_& m);      // frame
void bind_synth(py::module_& m);      // synth, TRUTH_DTYPE

/// evlife.read's body: every event of `path` that `options` select (reader_options).
py::array read_events(const std::string& path, const io::ReaderOptions& options);

/// A str, bytes or os.PathLike as the file name's bytes (os.fsencode: a name
/// that is not UTF-8 stays the file's), as evlife.read's `path` takes it.
inline std::string path_from_python(const py::handle& path) {
  try {
    return py::cast<std::filesystem::path>(path).string();
  } catch (const py::cast_error&) {  // pybind's RuntimeError otherwise
    // A name (str, bytes, os.PathLike) with a NUL in it: its value's fault, not its type's.
    std::string name;
    try {
      const py::module_ os = py::module_::import("os");
      name = py::bytes(os.attr("fsencode")(os.attr("fspath")(path)));
    } catch (const py::error_already_set&) {  // no path at all: the TypeError below
    }
    if (name.find('\0') != std::string::npos) throw py::value_error("path: embedded null byte");
    const bool file_object = py::hasattr(path, "read") || py::hasattr(path, "write");
    throw py::type_error("expected a path (str, bytes or os.PathLike), got " +
                         py::str(py::type::of(path).attr("__name__")).cast<std::string>() +
                         (file_object ? " (a file object: give its name)" : ""));
  }
}

/// A reader's skipped (non-event) records by kind, {kind: count}.
py::dict skipped_kinds_dict(const std::vector<io::SkippedKindCount>& kinds);

}  // namespace evlife::python
