#include "dtypes.h"

#include <cstdint>

namespace evlife::python {
namespace {

// Offsets from the C++ structs themselves: the layout is stated once.
py::dtype make_event_dtype() {
  py::dict d;
  d["names"] = py::make_tuple("t", "x", "y", "p");
  d["formats"] = py::make_tuple("<i8", "<u2", "<u2", "i1");
  d["offsets"] = py::make_tuple(offsetof(Event, t_us), offsetof(Event, x), offsetof(Event, y),
                                offsetof(Event, p));
  d["itemsize"] = sizeof(Event);
  return py::dtype::from_args(d);
}

py::dtype make_augmented_dtype() {
  constexpr std::size_t e = offsetof(AugmentedEvent, event);
  py::dict d;
  d["names"] = py::make_tuple("t", "x", "y", "p", "lifetime", "vx", "vy", "prediction_error");
  d["formats"] = py::make_tuple("<i8", "<u2", "<u2", "i1", "<f4", "<f4", "<f4", "<f4");
  d["offsets"] = py::make_tuple(e + offsetof(Event, t_us), e + offsetof(Event, x),
                                e + offsetof(Event, y), e + offsetof(Event, p),
                                offsetof(AugmentedEvent, lifetime_us),
                                offsetof(AugmentedEvent, vx_px_s), offsetof(AugmentedEvent, vy_px_s),
                                offsetof(AugmentedEvent, prediction_error_us));
  d["itemsize"] = sizeof(AugmentedEvent);
  return py::dtype::from_args(d);
}

}  // namespace

// Leaked on purpose: a static py::object would be released after the
// interpreter is gone.
py::dtype event_dtype() {
  static auto* dtype = new py::dtype(make_event_dtype());
  return *dtype;
}

py::dtype augmented_dtype() {
  static auto* dtype = new py::dtype(make_augmented_dtype());
  return *dtype;
}

bool is_exact(const py::array& a, const py::dtype& dtype) {
  if (a.ndim() != 1) return false;
  if (!a.dtype().attr("__eq__")(dtype).cast<bool>()) return false;
  if (a.shape(0) > 1 && a.strides(0) != dtype.itemsize()) return false;
  return reinterpret_cast<std::uintptr_t>(a.data()) % alignof(std::int64_t) == 0;
}

void bind_dtypes(py::module_& m) {
  m.attr("EVENT_DTYPE") = event_dtype();
  m.attr("AUGMENTED_DTYPE") = augmented_dtype();
}

}  // namespace evlife::python
