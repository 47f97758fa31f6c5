#include "evlife/io/augmented_event_reader.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "augmented_bin_format.h"
#include "augmented_formats.h"
#include "evlife_bin_magic.h"
#include "input_file.h"

namespace evlife::io {

namespace {

// The first bytes of the file (fewer for a shorter one).
std::string head_of(const std::string& path) {
  char head[8] = {};
  const detail::InputFile file(path);
  const std::size_t got = file.read_at(0, std::as_writable_bytes(std::span(head)));
  return std::string(head, got);
}

// evlife's .bin by its magic or by its name (whose errors are then this
// file's); nullptr for anything else.
std::unique_ptr<AugmentedEventReader> open_as_bin(const std::string& path, const std::string& head) {
  if (head == detail::augmented_bin::kMagic) return detail::open_augmented_bin_reader(path);
  if (detail::named_like_augmented_bin(path)) throw ReadError(path, 0, -1, detail::not_augmented_bin_reason(head));
  return nullptr;
}

}  // namespace

bool names_augmented_bin(const std::string& path) { return detail::named_like_augmented_bin(path); }

std::unique_ptr<AugmentedEventReader> open_augmented_reader(const std::string& path) {
  const std::string head = head_of(path);
  if (auto bin = open_as_bin(path, head)) return bin;
  if (detail::starts_like_hdf5(head)) {
    if (auto h5 = detail::open_augmented_hdf5_reader(path)) return h5;
    throw ReadError(path, -1, -1, "HDF5 events without evlife's lifetime, vx, vy and prediction_error columns");
  }
  return detail::open_augmented_csv_reader(path);  // checks its header
}

std::unique_ptr<AugmentedEventReader> open_if_augmented(const std::string& path) {
  std::string head;
  try {
    head = head_of(path);
  } catch (const ReadError&) {  // no file (a folder: a ROS 2 bag): the caller's other readers say
    return nullptr;
  }
  if (auto bin = open_as_bin(path, head)) return bin;
  try {
    if (detail::starts_like_hdf5(head)) return detail::open_augmented_hdf5_reader(path);
    return detail::open_augmented_csv_reader(path);
  } catch (const AugmentedColumnsError&) {  // evlife's output, damaged: named, never read as plain events
    throw;
  } catch (const ReadError&) {  // not evlife's output: the caller's other readers say what it is
    return nullptr;
  }
}

std::optional<std::string> augmented_values_fault(const AugmentedEvent& a) {
  const auto text = [](float v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", static_cast<double>(v));
    return std::string(buf);
  };
  if (!(a.lifetime_us >= 0.0f) || std::isinf(a.lifetime_us))
    return "lifetime " + text(a.lifetime_us) + " us (0 for noise, else positive and finite)";
  if (!std::isfinite(a.vx_px_s) || !std::isfinite(a.vy_px_s))
    return "velocity (" + text(a.vx_px_s) + ", " + text(a.vy_px_s) + ") px/s (finite)";
  if (std::isinf(a.prediction_error_us)) return "prediction_error " + text(a.prediction_error_us) + " us";
  return std::nullopt;
}

RecordFault first_unreadable_record(std::span<const AugmentedEvent> records, SensorSize sensor,
                                    std::int64_t last_t_us) {
  for (std::size_t i = 0; i < records.size(); ++i) {
    const Event& e = records[i].event;
    if (e.p != 1 && e.p != -1)
      return {i, "corrupt record: polarity " + std::to_string(e.p) + " (an augmented event's is +1 or -1)"};
    if (auto fault = augmented_values_fault(records[i])) return {i, "corrupt record: " + *fault};
    if (sensor.width > 0 && !sensor.contains(e.x, e.y)) {
      return {i, "event at (x " + std::to_string(e.x) + ", y " + std::to_string(e.y) + ") is outside the " +
                     std::to_string(sensor.width) + "x" + std::to_string(sensor.height) + " sensor"};
    }
    if (e.t_us < last_t_us) {
      return {i, "timestamp goes backwards: " + std::to_string(e.t_us) + " us after " + std::to_string(last_t_us) +
                     " us"};
    }
    last_t_us = e.t_us;
  }
  return {records.size(), {}};
}

SensorSize sensor_size_of_augmented(const std::string& path, std::optional<SensorSize> user) {
  // The caller sizes per-pixel planes by it (render, eval): a corrupt header
  // or a stray coordinate must not ask for gigabytes.
  const auto within_cameras = [&](SensorSize s, const std::string& whence) {
    if (!s.within_camera_limits()) {
      throw ReadError(path, -1, -1,
                      whence + " " + std::to_string(s.width) + "x" + std::to_string(s.height) +
                          ", more than any camera (at most " + std::to_string(kMaxSensorSide) +
                          " px a side): give --sensor WxH (events outside it are counted and skipped)");
    }
    return s;
  };
  const std::unique_ptr<AugmentedEventReader> reader = open_augmented_reader(path);
  // A size the file states wins, as for every recording (`process`): --sensor
  // is for files that state none, or one no camera has.
  const std::optional<SensorSize> stated = reader->sensor_size();
  if (stated && (stated->within_camera_limits() || !user)) return within_cameras(*stated, "states a sensor of");
  if (user) return *user;
  std::vector<AugmentedEvent> buf(4096);
  SensorSize s{0, 0};
  try {
    while (const std::size_t n = reader->read(buf)) {
      for (std::size_t i = 0; i < n; ++i) {
        s.width = std::max(s.width, buf[i].event.x + 1);
        s.height = std::max(s.height, buf[i].event.y + 1);
      }
    }
  } catch (const ReadError&) {
    // A fault after some events: the sensor of the events before it, as for
    // recordings (sensor_size_from_data); the drawing pass shows those, then
    // reports the fault (it drew nothing).
    if (s.width == 0) throw;
  }
  if (s.width == 0) throw ReadError(path, -1, -1, "holds no event: cannot tell the sensor size (give --sensor WxH)");
  return within_cameras(s, "has events spanning");
}

}  // namespace evlife::io
