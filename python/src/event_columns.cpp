#include "event_columns.h"

#include <algorithm>
#include <string>

#include "dtypes.h"

namespace evlife::python {
namespace {

// ", it has fields ts, x, y, polarity": the names an array (dtype.names), a
// dict (keys) or a DataFrame (columns) has, for the message of a missing one;
// "" when it has none to tell.
std::string fields_it_has(const py::handle& events) {
  py::object names = py::none();
  try {
    if (py::hasattr(events, "dtype")) names = events.attr("dtype").attr("names");
    else if (py::hasattr(events, "columns")) names = events.attr("columns");
    else if (py::isinstance<py::dict>(events)) names = py::reinterpret_borrow<py::dict>(events).attr("keys")();
  } catch (const py::error_already_set&) {
    return "";
  }
  if (names.is_none()) return "";
  std::string text;
  std::size_t count = 0;
  for (const py::handle n : names) {
    if (++count > 12) {
      text += ", ...";
      break;
    }
    text += (text.empty() ? "" : ", ") + py::str(n).cast<std::string>();
  }
  return text.empty() ? "" : ", it has fields " + text;
}

Column column(const py::handle& events, const char* name, py::object& keep, bool allow_bool) {
  py::object col;
  try {
    col = events[py::str(name)];
  } catch (const py::error_already_set& e) {
    if (!e.matches(PyExc_KeyError) && !e.matches(PyExc_ValueError) &&
        !e.matches(PyExc_IndexError) && !e.matches(PyExc_TypeError)) {
      throw;
    }
    // (Its fields named: ts, polarity or x_pos, evlife.read's spellings of a file's columns, are not taken here.)
    throw py::type_error(std::string("events: no field '") + name +
                         "' (expected an array with fields t, x, y, p, e.g. from evlife.read" + fields_it_has(events) +
                         ")");
  }
  py::array a = py::array::ensure(col);
  if (!a || a.ndim() != 1) {
    throw py::type_error(std::string("events['") + name + "']: expected a 1-D array");
  }
  const py::dtype dt = a.dtype();
  const char kind = dt.kind();
  if (!(kind == 'i' || kind == 'u' || (allow_bool && kind == 'b'))) {
    throw py::type_error(std::string("events['") + name + "']: expected integers" +
                         (allow_bool ? " or bools" : "") + ", got dtype " +
                         py::str(py::handle(dt)).cast<std::string>() +
                         (name[0] == 't' ? " (timestamps are integer microseconds)" : ""));
  }
  if (dt.itemsize() > 1 && !dt.attr("isnative").cast<bool>()) {
    a = py::array::ensure(a.attr("astype")(dt.attr("newbyteorder")("=")));
  }
  keep = a;
  Column c;
  c.base = static_cast<const char*>(a.data());
  c.stride = a.strides(0);
  c.kind = kind;
  c.size = static_cast<int>(a.dtype().itemsize());
  return c;
}

}  // namespace

EventColumns event_columns(const py::handle& events_given) {
  // A memoryview of an events array as that array (frame and write take one):
  // c.events keeps it alive.
  EventColumns c;
  c.events = PyMemoryView_Check(events_given.ptr())
                 ? py::object(py::module_::import("numpy").attr("asarray")(events_given))
                 : py::reinterpret_borrow<py::object>(events_given);
  const py::object& events = c.events;
  if (py::isinstance<py::array>(events)) {
    const auto a = py::reinterpret_borrow<py::array>(events);
    if (is_exact(a, event_dtype())) c.exact = static_cast<const Event*>(a.data());
  }
  c.t = column(events, "t", c.keep[0], false);
  c.x = column(events, "x", c.keep[1], false);
  c.y = column(events, "y", c.keep[2], false);
  c.p = column(events, "p", c.keep[3], true);
  c.p_is_bool = c.p.kind == 'b';
  c.size = static_cast<std::size_t>(py::len(c.keep[0]));
  for (int i = 1; i < 4; ++i) {
    if (static_cast<std::size_t>(py::len(c.keep[i])) != c.size) {
      throw py::value_error("events: the columns t, x, y, p differ in length");
    }
  }
  return c;
}

EventCheck check_events(const EventColumns& c, SensorSize sensor, std::int64_t last_t_us) noexcept {
  EventCheck r;
  r.convert = c.exact == nullptr || c.p_is_bool;
  std::int64_t last = last_t_us;
  std::size_t first_zero = SIZE_MAX, first_minus_one = SIZE_MAX;  // polarity conventions seen
  for (std::size_t i = 0; i < c.size; ++i) {
    std::int64_t t, x, y, p;
    if (c.exact) {
      const Event& e = c.exact[i];
      t = e.t_us, x = e.x, y = e.y, p = e.p;
      // Bytes NumPy left in the padding: converted, so that the output's are zero.
      if ((e.reserved[0] | e.reserved[1] | e.reserved[2]) != 0) r.convert = true;
    } else {
      if (c.t.exceeds_int64(i)) {
        r.bad_index = i;
        r.what = "timestamp " + std::to_string(c.t.get_unsigned(i)) +
                 " us does not fit a signed 64-bit integer (evlife's time type)";
        break;
      }
      t = c.t.get(i), x = c.x.get(i), y = c.y.get(i), p = c.p.get(i);
    }
    if (!within_event_time_range(t)) {  // the estimator would label it noise, uncounted here
      r.bad_index = i;
      r.what = "timestamp " + std::to_string(t) + " us is beyond +-2^62 us (evlife's time range)";
      break;
    }
    if (x < 0 || y < 0 || x >= sensor.width || y >= sensor.height) {
      r.bad_index = i;
      // (As written: a uint64 beyond INT64_MAX, not its clamped value.)
      r.what = event_position_text(c, i) + " is outside the " + std::to_string(sensor.width) + "x" +
               std::to_string(sensor.height) + " sensor";
      break;
    }
    if (t < last) {
      r.bad_index = i;
      r.what = "timestamp goes backwards: " + std::to_string(t) + " us after " +
               std::to_string(last) + " us";
      break;
    }
    if (!c.p_is_bool) {
      if (p == 0) {
        r.convert = true;  // 0/1 polarity
        if (first_zero == SIZE_MAX) first_zero = i;
      } else if (p == -1) {
        if (first_minus_one == SIZE_MAX) first_minus_one = i;
      } else if (p != 1) {
        r.bad_index = i;
        r.what = "polarity " + (c.exact ? std::to_string(p) : c.p.text(i)) + " is none of +1/-1, 0/1 or a bool";
        break;
      }
      if (first_zero != SIZE_MAX && first_minus_one != SIZE_MAX) {
        r.bad_index = i;
        r.what = "polarity mixes the 0/1 and +1/-1 conventions (0 at event " + std::to_string(first_zero) +
                 ", -1 at event " + std::to_string(first_minus_one) + ")";
        break;
      }
    }
    last = t;
  }
  return r;
}

void convert_events(const EventColumns& c, std::size_t first, std::span<Event> out) noexcept {
  for (std::size_t k = 0; k < out.size(); ++k) {
    const std::size_t i = first + k;
    Event& e = out[k];
    e.t_us = c.t.get(i);
    e.x = static_cast<std::uint16_t>(c.x.get(i));
    e.y = static_cast<std::uint16_t>(c.y.get(i));
    e.p = c.p.get(i) > 0 ? 1 : -1;
  }
}

SensorSize sensor_from_events(const EventColumns& c) noexcept {
  std::int64_t max_x = -1, max_y = -1;
  for (std::size_t i = 0; i < c.size; ++i) {
    max_x = std::max(max_x, c.exact ? c.exact[i].x : c.x.get(i));
    max_y = std::max(max_y, c.exact ? c.exact[i].y : c.y.get(i));
  }
  // Beyond any camera (an x near 2^63 would overflow + 1): the largest sensor,
  // outside which the event is then named by the conversion's check.
  const auto side = [](std::int64_t max) {
    return max < 0 ? 0 : static_cast<int>(std::min<std::int64_t>(max, kMaxSensorSide - 1) + 1);
  };
  return {side(max_x), side(max_y)};
}

std::size_t first_beyond_any_camera(const EventColumns& c) noexcept {
  for (std::size_t i = 0; i < c.size; ++i) {
    const std::int64_t x = c.exact ? c.exact[i].x : c.x.get(i), y = c.exact ? c.exact[i].y : c.y.get(i);
    if (x >= kMaxSensorSide || y >= kMaxSensorSide) return i;
  }
  return SIZE_MAX;
}

std::string event_position_text(const EventColumns& c, std::size_t i) {
  // (As written: a uint64 beyond INT64_MAX, not its clamped value.)
  return "event at (x " + (c.exact ? std::to_string(c.exact[i].x) : c.x.text(i)) + ", y " +
         (c.exact ? std::to_string(c.exact[i].y) : c.y.text(i)) + ")";
}

}  // namespace evlife::python
