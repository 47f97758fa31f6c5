// The compiled part of the Python package `evlife` (evlife/__init__.py
// re-exports it with the pure-Python parts).
#include <pybind11/pybind11.h>

#include "bindings.h"
#include "dtypes.h"
#include "errors.h"
#include "evlife/io/event_reader.h"
#include "evlife/io/hdf5_writer.h"
#include "options.h"

PYBIND11_MODULE(_evlife, m) {
  namespace py = pybind11;
  using namespace evlife::python;
  m.doc() = "evlife's C++ core: readers, the lifetime estimator and the renderer over NumPy arrays.";
  bind_errors(m);
  bind_dtypes(m);
  bind_options(m);
  bind_reader(m);
  bind_estimator(m);
  bind_frame(m);
  bind_synth(m);
  m.def(
      "formats",
      [] {
        py::list out;
        for (const auto& f : evlife::io::known_event_formats()) {
          out.append(py::make_tuple(std::string(f.name), std::string(f.description)));
        }
        return out;
      },
      "Every input format, [(name, description)], in sniffing order.");
  m.def("_hdf5_exit_would_crash", &evlife::io::hdf5_exit_would_crash,
        "True once an HDF5 file failed to close: libhdf5 1.10's exit handler would crash.");
  m.def("_hdf5_exit_would_loop", &evlife::io::hdf5_exit_would_loop,
        "True once an HDF5 file could not be created: libhdf5 1.10's exit handler would print noise.");
}
