#include "evlife/io/available_memory.h"

#include <sys/resource.h>

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

namespace {

// What an address-space limit (`ulimit -v`) leaves this process to map: the
// limit less what it maps already (VmSize). None without a limit.
std::optional<std::uint64_t> mappable_bytes_left() {
  rlimit limit{};
  if (getrlimit(RLIMIT_AS, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return std::nullopt;
  std::ifstream status("/proc/self/status");
  std::string key;
  while (status >> key) {
    if (key == "VmSize:") {
      std::uint64_t kib = 0;
      status >> kib;
      const std::uint64_t mapped = kib * 1024;
      return limit.rlim_cur > mapped ? limit.rlim_cur - mapped : 0;
    }
    status.ignore(1 << 12, '\n');
  }
  return limit.rlim_cur;
}

}  // namespace

std::optional<std::string> beyond_available_memory(std::uint64_t bytes) {
  if (const std::optional<std::uint64_t> left = mappable_bytes_left(); left && bytes > *left)
    return ", more than the " + gigabytes_text(*left) + " this process may still map (its address-space limit, ulimit -v)";
  const std::optional<std::uint64_t> available = available_memory_bytes();
  if (!available || bytes <= *available) return std::nullopt;
  return ", more than the " + gigabytes_text(*available) + " of memory available";
}

}  // namespace evlife::io
