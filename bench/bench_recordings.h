// The estimator benchmarks' inputs, loaded once per process: the shared
// reference recordings (stripes, garfield) and a synthetic 1280x720 scene.
#pragma once

#include <cstdio>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "evlife/algo/event.h"
#include "evlife/io/event_reader.h"
#include "evlife/io/synthetic_scene.h"

namespace evlife::bench {

struct Recording {
  std::vector<Event> events;
  SensorSize sensor;
};

inline const Recording& recording(const std::string& name) {
  static std::map<std::string, Recording> cache;
  auto it = cache.find(name);
  if (it != cache.end()) return it->second;
  Recording r;
  if (name.rfind("synthetic_", 0) == 0) {  // synthetic_WxH: the `large` preset on a WxH sensor
    int width = 0, height = 0;
    char end = 0;
    if (std::sscanf(name.c_str() + 10, "%dx%d%c", &width, &height, &end) != 2 || width < 1 || height < 1 ||
        width > 65535 || height > 65535) {
      throw std::invalid_argument("not synthetic_WxH with W, H in 1..65535");
    }
    r.sensor = {width, height};
    r.events = io::generate_scene(io::large_scene(r.sensor, 200'000, 1)).events;
  } else {
    const std::string path = std::string(EVLIFE_SHARED_DATA_DIR) + "/reference/" + name + ".mat";
    auto reader = io::open_event_reader(path);
    r.sensor = reader->sensor_size().value_or(SensorSize{128, 128});
    std::vector<Event> buf(1 << 16);
    while (const std::size_t n = reader->read(buf)) r.events.insert(r.events.end(), buf.begin(), buf.begin() + n);
  }
  return cache.emplace(name, std::move(r)).first->second;
}

}  // namespace evlife::bench
