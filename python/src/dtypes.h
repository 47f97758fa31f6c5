// NumPy views of the C++ event types: the structured dtypes whose layout is
// exactly evlife::Event (16 B) and evlife::AugmentedEvent (32 B), so arrays
// pass to and from the C++ code without per-event conversion or objects.
#pragma once

#include <pybind11/numpy.h>

#include <cstddef>
#include <memory>
#include <vector>

#include "evlife/algo/event.h"

namespace evlife::python {

namespace py = pybind11;

/// t (int64 µs), x, y (uint16), p (int8, +1/-1); itemsize 16.
py::dtype event_dtype();
/// The fields above, then lifetime, vx, vy, prediction_error (float32:
/// µs, px/s, px/s, µs; NaN = no prediction); itemsize 32.
py::dtype augmented_dtype();

/// True when `a` is a 1-D, C-contiguous, aligned array of exactly `dtype`.
bool is_exact(const py::array& a, const py::dtype& dtype);

/// A NumPy array that owns `v`'s buffer (no copy): the vector moves into a
/// capsule freed with the array.
template <class T>
py::array adopt(std::vector<T>&& v, const py::dtype& dtype) {
  auto* owned = new std::vector<T>(std::move(v));
  py::capsule owner(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array(dtype, {static_cast<py::ssize_t>(owned->size())},
                   {static_cast<py::ssize_t>(sizeof(T))}, owned->data(), owner);
}

void bind_dtypes(py::module_& m);

}  // namespace evlife::python
