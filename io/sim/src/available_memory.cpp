#include <cstdint>
#include <fstream>
#include <optional>
#include <string>

#include "evlife/io/synthetic_scene.h"

namespace evlife::io {

std::optional<std::uint64_t> available_memory_bytes() {
  std::ifstream meminfo("/proc/meminfo");
  std::string key;
  std::uint64_t kib = 0;
  std::string unit;
  while (meminfo >> key >> kib >> unit) {
    if (key == "MemAvailable:") return kib * 1024;
  }
  return std::nullopt;
}

}  // namespace evlife::io
