#include "memory_check.h"

#include <cstdint>
#include <cstdio>
#include <fstream>

#include "evlife/algo/lifetime_estimator.h"

namespace evlife::cli {
namespace {

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

std::string gigabytes(std::uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f GB", static_cast<double>(bytes) * 1e-9);
  return text;
}

}  // namespace

std::optional<std::string> memory_shortfall(std::uint64_t bytes) {
  const std::optional<std::uint64_t> available = available_memory_bytes();
  if (!available || bytes <= *available) return std::nullopt;
  return gigabytes(bytes) + ", more than the " + gigabytes(*available) + " of memory available";
}

std::optional<std::string> scene_memory_refusal(std::uint64_t bytes, bool whole) {
  const std::optional<std::string> shortfall = memory_shortfall(bytes);
  if (!shortfall) return std::nullopt;
  return "the scene's background activity and hot pixels need " + *shortfall +
         (whole ? " (the textured scene is generated whole): lower --noise-rate, the sensor or --duration"
                : " (for each generation slice): lower --noise-rate or the sensor");
}

std::optional<std::string> estimator_memory_refusal(SensorSize sensor, int estimators) {
  const std::uint64_t each = LifetimeEstimator::state_bytes(sensor);
  const std::uint64_t needed = each * static_cast<std::uint64_t>(estimators);
  const std::optional<std::uint64_t> available = available_memory_bytes();
  if (!available || needed <= *available) return std::nullopt;
  std::string text = "a " + std::to_string(sensor.width) + "x" + std::to_string(sensor.height) + " sensor needs " +
                     gigabytes(each) + " of estimator state";
  if (estimators > 1) text += " per worker (" + std::to_string(estimators) + " workers: " + gigabytes(needed) + ")";
  return text + ", more than the " + gigabytes(*available) + " of memory available";
}

}  // namespace evlife::cli
