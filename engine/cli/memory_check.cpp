#include "memory_check.h"

#include <cstdint>
#include <string_view>

#include "evlife/algo/lifetime_estimator.h"

namespace evlife::cli {
namespace {

using io::beyond_available_memory;
using io::gigabytes_text;

std::optional<std::string> background_refusal(std::uint64_t bytes, std::string_view held, std::string_view lower) {
  const std::optional<std::string> beyond = beyond_available_memory(bytes);
  if (!beyond) return std::nullopt;
  return "the scene's background activity and hot pixels need " + gigabytes_text(bytes) + *beyond + " (" +
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
                     gigabytes_text(each) + " of estimator state";
  if (estimators > 1) text += " per worker (" + std::to_string(estimators) + " workers: " + gigabytes_text(needed) + ")";
  return text + *beyond;
}

}  // namespace evlife::cli
