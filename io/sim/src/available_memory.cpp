#include "evlife/io/available_memory.h"

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <optional>
#include <string>

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

std::string gigabytes_text(std::uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f GB", static_cast<double>(bytes) * 1e-9);
  return text;
}

std::optional<std::string> beyond_available_memory(std::uint64_t bytes) {
  const std::optional<std::uint64_t> available = available_memory_bytes();
  if (!available || bytes <= *available) return std::nullopt;
  return ", more than the " + gigabytes_text(*available) + " of memory available";
}

}  // namespace evlife::io
