#include "errors.h"

#include <cerrno>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include "evlife/config/config.h"
#include "evlife/io/stop.h"
#include "evlife/io/write_error.h"

namespace evlife::python {
namespace {

PyObject* g_input_error = nullptr;  // evlife.InputError, owned by the module
PyObject* g_interrupted = nullptr;  // evlife.Interrupted

constexpr const char* kInterruptedDoc =
    "Ctrl-C (SIGINT) during a long call: a KeyboardInterrupt, raised between\n"
    "blocks of 65536 events, with what was done: partial (the outputs of the\n"
    "events processed, or None), events_processed, events_written (how many\n"
    "events process_file's output holds, else None). LifetimeEstimator.process:\n"
    "its state includes the events processed; go on with events[events_processed:].\n"
    "synth: partial is None, events_processed the events generated (dropped).\n"
    "On the main thread, with Python's default SIGINT handler (a handler of your\n"
    "own runs after the call, as before).";
constexpr auto kSignalCheckPeriod = std::chrono::milliseconds(100);

constexpr const char* kInputErrorDoc =
    "Bad input: a file or array evlife cannot use (unknown format, corrupt or\n"
    "truncated data, an event outside the sensor, timestamps going backwards).\n"
    "A ValueError. The message is the command line's (file, byte offset, event\n"
    "index); the attributes path, byte_offset, event_index (-1 = unknown) and\n"
    "partial (the good events before the fault, or None) say the same as data;\n"
    "events_written: how many events process_file's output holds (else None).";

/// A reader's message names the command line's flags; in Python they are
/// keywords: said after it, for the flags it names.
std::string with_python_keywords(const std::string& message) {
  static constexpr std::pair<std::string_view, std::string_view> kFlags[] = {
      {"--topic", "topic="}, {"--sensor", "sensor=(width, height)"}, {"--time-unit", "time_unit="}};
  std::string said;
  for (const auto& [flag, keyword] : kFlags) {
    if (message.find(flag) == std::string::npos) continue;
    said += (said.empty() ? "" : ", ") + std::string(flag) + " is " + std::string(keyword);
  }
  return said.empty() ? message : message + " (in Python " + said + ")";
}

}  // namespace

void raise_input_error(const io::ReadError& e, py::object partial) {
  std::error_code ec;
  // (An empty name too, as Python's open(""): no file is named so.)
  const bool missing = e.event_index() < 0 && e.byte_offset() < 0 &&
                       (e.path().empty() || !std::filesystem::exists(e.path(), ec));
  if (missing) {
    // errno for `e.errno == errno.ENOENT`; no filename or strerror, which
    // would make str() Python's "[Errno 2] ...", not the CLI's message.
    py::object error = py::reinterpret_borrow<py::object>(PyExc_FileNotFoundError)(e.what());
    error.attr("errno") = ENOENT;
    PyErr_SetObject(PyExc_FileNotFoundError, error.ptr());
    throw py::error_already_set();
  }
  py::object error = py::reinterpret_borrow<py::object>(g_input_error)(with_python_keywords(e.what()));
  // A file name that is not UTF-8 as os.fsdecode gives it (the message quotes it escaped).
  error.attr("path") = py::reinterpret_steal<py::object>(PyUnicode_DecodeFSDefault(e.path().c_str()));
  error.attr("byte_offset") = e.byte_offset();
  error.attr("event_index") = e.event_index();
  error.attr("partial") = std::move(partial);
  error.attr("events_written") = py::none();  // process_file sets it (the stub declares it)
  PyErr_SetObject(g_input_error, error.ptr());
  throw py::error_already_set();
}

SignalCheck::SignalCheck(bool long_call) {
  if (!long_call) return;
  const py::module_ threading = py::module_::import("threading");
  const py::module_ signal = py::module_::import("signal");
  enabled_ = threading.attr("current_thread")().is(threading.attr("main_thread")()) &&
             signal.attr("getsignal")(signal.attr("SIGINT")).is(signal.attr("default_int_handler"));
}

bool SignalCheck::pending() {
  if (interrupted_ || !enabled_) return interrupted_;
  const auto now = std::chrono::steady_clock::now();
  if (now < next_check_) return false;
  next_check_ = now + kSignalCheckPeriod;
  const py::gil_scoped_acquire gil;
  return interrupted_ = PyOS_InterruptOccurred() != 0;
}

bool SignalCheck::pending_now() {
  if (!interrupted_ && enabled_) interrupted_ = PyOS_InterruptOccurred() != 0;
  return interrupted_;
}

IoStopScope::IoStopScope(SignalCheck& signals) noexcept {
  io::set_thread_stop_check(
      [](void* context) noexcept {
        try {
          return static_cast<SignalCheck*>(context)->pending();
        } catch (...) {  // (taking the GIL at the interpreter's end)
          return false;
        }
      },
      &signals);
}

IoStopScope::~IoStopScope() { io::set_thread_stop_check(nullptr, nullptr); }

void raise_interrupted_while_waiting(const std::string& who, const char* object, const char* nothing,
                                     py::object partial) {
  SignalCheck::raise(who + ": interrupted while another thread's call held " + object + "; " + nothing,
                     std::move(partial), 0, py::none());
}

void SignalCheck::raise(const std::string& message, py::object partial, std::uint64_t events_processed,
                        py::object events_written) {
  py::object error = py::reinterpret_borrow<py::object>(g_interrupted)(message);
  error.attr("partial") = std::move(partial);
  error.attr("events_processed") = events_processed;
  error.attr("events_written") = std::move(events_written);
  PyErr_SetObject(g_interrupted, error.ptr());
  throw py::error_already_set();
}

// The temporary copy of the named pipe this thread's call reads, and the
// pipe's name (_streams.py sets them around the call): per thread, where
// warnings.catch_warnings would redirect every thread's warnings.
thread_local std::string t_stream_copy, t_stream_name;

void warn_at_callers_line(std::string text, int stacklevel) {
  if (!t_stream_copy.empty()) {
    for (std::size_t at = text.find(t_stream_copy); at != std::string::npos;
         at = text.find(t_stream_copy, at + t_stream_name.size()))
      text.replace(at, t_stream_copy.size(), t_stream_name);
  }
  // Level 1 is the wrapper's own line in _streams.py; 2 the line that called evlife.
  if (PyErr_WarnEx(PyExc_RuntimeWarning, text.c_str(), stacklevel) != 0) throw py::error_already_set();
}

void bind_errors(py::module_& m) {
  g_input_error = PyErr_NewExceptionWithDoc("evlife.InputError", kInputErrorDoc, PyExc_ValueError,
                                            nullptr);
  m.attr("InputError") = py::handle(g_input_error);
  m.def(
      "_stream_alias",
      [](const std::string& copy, const std::string& name) {
        t_stream_copy = copy;
        t_stream_name = name;
      },
      py::arg("copy"), py::arg("name"),
      "Internal: this thread's calls name `copy` (a pipe's temporary copy) as `name` in their warnings; "
      "('', '') to end.");
  g_interrupted = PyErr_NewExceptionWithDoc("evlife.Interrupted", kInterruptedDoc, PyExc_KeyboardInterrupt, nullptr);
  m.attr("Interrupted") = py::handle(g_interrupted);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const io::ReadError& e) {
      try {
        raise_input_error(e);
      } catch (py::error_already_set& error) {
        error.restore();  // the InputError (or FileNotFoundError) becomes the raised one
      }
    } catch (const config::ConfigError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const io::WriteError& e) {
      // errno as data (`e.errno == errno.ENOSPC`); no filename or strerror,
      // which would make str() Python's "[Errno 28] ...", not the command
      // line's message (as for FileNotFoundError above).
      py::object error = py::reinterpret_borrow<py::object>(PyExc_OSError)(e.what());
      if (e.os_error() != 0) error.attr("errno") = e.os_error();
      PyErr_SetObject(PyExc_OSError, error.ptr());
    }
  });
}

}  // namespace evlife::python
