#include "memory_check.h"

#include <cstdint>
#include <cstdio>
#include <string_view>

#include "evlife/algo/lifetime_estimator.h"

namespace evlife::cli {
namespace {

std::string gigabytes(std::uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f GB", static_cast<double>(bytes) * 1e-9);
  return text;
}

// ", more than the A GB of memory available" when `bytes` exceed
// MemAvailable; nothing when they fit or it is unknown.
std::optional<std::string> beyond_available_memory(std::uint64_t bytes) {
  const std::optional<std::uint64_t> available = io::available_memory_bytes();
  if (!available || bytes <= *available) return std::nullopt;
  return ", more than the " + gigabytes(*available) + " of memory available";
}

std::optional<std::string> background_refusal(std::uint64_t bytes, std::string_view held, std::string_view lower) {
  const std::optional<std::string> beyond = beyond_available_memory(bytes);
  if (!beyond) return std::nullopt;
  return "the scene's background activity and hot pixels need " + gigabytes(bytes) + *beyond + " (" +
         std::string(held) + "): lower " + std::string(lower);
}

}  // namespace

std::optional<std::string> scene_memory_refusal(const io::SceneSpec& spec) {
  return background_refusal(io::scene_reader_memory_bytes(spec), "for each generation slice",
                            "--noise-rate or the sensor");
}

std::optional<std::string> scene_memory_refusal(const io::TexturedSceneSpec& spec) {
  return background_refusal(io::textured_scene_memory_bytes(spec), "the textured scene is generated whole",
                            "--noise-rate, the sensor or --duration");
}

std::optional<std::string> estimator_memory_refusal(SensorSize sensor, int estimators) {
  const std::uint64_t each = LifetimeEstimator::state_bytes(sensor);
  const std::uint64_t needed = each * static_cast<std::uint64_t>(estimators);
  const std::optional<std::string> beyond = beyond_available_memory(needed);
  if (!beyond) return std::nullopt;
  std::string text = "a " + std::to_string(sensor.width) + "x" + std::to_string(sensor.height) + " sensor needs " +
                     gigabytes(each) + " of estimator state";
  if (estimators > 1) text += " per worker (" + std::to_string(estimators) + " workers: " + gigabytes(needed) + ")";
  return text + *beyond;
}

std::optional<std::string> frame_memory_refusal(int width_px, int height_px) {
  const std::uint64_t bytes = std::uint64_t{3} * static_cast<std::uint64_t>(width_px) * static_cast<std::uint64_t>(height_px);
  const std::optional<std::string> beyond = beyond_available_memory(bytes);
  if (!beyond) return std::nullopt;
  return "a frame of " + std::to_string(width_px) + "x" + std::to_string(height_px) + " px needs at least " +
         gigabytes(bytes) + *beyond;
}

}  // namespace evlife::cli
