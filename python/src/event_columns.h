// Any array-like with t, x, y, p columns (a structured array, a dict of
// arrays, a pandas DataFrame) as raw strided integer columns that C++ can
// read without the GIL, checked and converted into evlife::Event blocks.
#pragma once

#include <pybind11/numpy.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>

#include "evlife/algo/event.h"

namespace evlife::python {

namespace py = pybind11;

/// One integer (or bool) column: base pointer, stride, element type.
struct Column {
  const char* base = nullptr;
  py::ssize_t stride = 0;
  char kind = 'i';  // 'i' signed, 'u' unsigned, 'b' bool
  int size = 8;

  /// An unsigned 64-bit value above INT64_MAX (get() would clamp it).
  bool exceeds_int64(std::size_t i) const noexcept {
    return kind == 'u' && size == 8 && get_unsigned(i) > static_cast<std::uint64_t>(INT64_MAX);
  }

  /// The value as written, for messages (an unsigned one above INT64_MAX too).
  std::string text(std::size_t i) const {
    return exceeds_int64(i) ? std::to_string(get_unsigned(i)) : std::to_string(get(i));
  }

  std::uint64_t get_unsigned(std::size_t i) const noexcept {
    return load<std::uint64_t>(base + static_cast<py::ssize_t>(i) * stride);
  }

  std::int64_t get(std::size_t i) const noexcept {
    const char* p = base + static_cast<py::ssize_t>(i) * stride;
    switch (kind) {
      case 'b': return load<std::uint8_t>(p) != 0;
      case 'u':
        switch (size) {
          case 1: return load<std::uint8_t>(p);
          case 2: return load<std::uint16_t>(p);
          case 4: return load<std::uint32_t>(p);
          default: {
            const auto v = load<std::uint64_t>(p);
            return v > static_cast<std::uint64_t>(INT64_MAX) ? INT64_MAX : static_cast<std::int64_t>(v);
          }
        }
      default:
        switch (size) {
          case 1: return load<std::int8_t>(p);
          case 2: return load<std::int16_t>(p);
          case 4: return load<std::int32_t>(p);
          default: return load<std::int64_t>(p);
        }
    }
  }

 private:
  template <class T>
  static T load(const char* p) noexcept {  // any alignment, any stride
    T v;
    std::memcpy(&v, p, sizeof v);
    return v;
  }
};

/// The four columns of `events`, with references that keep them alive.
struct EventColumns {
  py::object keep[4];
  py::object events;  ///< what `exact` points into (a memoryview's array is made here)
  Column t, x, y, p;
  std::size_t size = 0;
  /// Non-null when `events` is already an exact evlife.EVENT_DTYPE array.
  const Event* exact = nullptr;
  bool p_is_bool = false;
};

/// Raises TypeError for a missing or non-integer column, ValueError for
/// columns of different lengths.
EventColumns event_columns(const py::handle& events);

/// What check_events finds.
struct EventCheck {
  std::size_t bad_index = SIZE_MAX;  ///< first event at fault, SIZE_MAX = none
  std::string what;                  ///< the fault, in the readers' words
  bool convert = false;              ///< polarity 0/1 or bool: convert into blocks
};

/// Checks every event (no GIL needed): coordinates inside `sensor`, time
/// within int64 and not going backwards from `last_t_us`, polarity +1/-1,
/// 0/1 or bool (one convention per call: 0 beside -1 is a mistake upstream).
EventCheck check_events(const EventColumns& c, SensorSize sensor, std::int64_t last_t_us) noexcept;

/// Events [first, first + out.size()) as evlife::Event (polarity +1/-1).
/// Only for checked columns.
void convert_events(const EventColumns& c, std::size_t first, std::span<Event> out) noexcept;

/// Largest x + 1 and y + 1 (the smallest sensor holding every event), each
/// at most kMaxSensorSide.
SensorSize sensor_from_events(const EventColumns& c) noexcept;

/// The first event with x or y beyond any camera (kMaxSensorSide or more):
/// where no sensor is given, a corrupt record; SIZE_MAX = none.
std::size_t first_beyond_any_camera(const EventColumns& c) noexcept;

/// "event at (x X, y Y)" of event i, the coordinates as written.
std::string event_position_text(const EventColumns& c, std::size_t i);

}  // namespace evlife::python
