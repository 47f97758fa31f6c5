#include "evlife/render/frame_memory.h"

#include <cstdint>

#include "evlife/io/available_memory.h"

namespace evlife::render {

std::optional<std::string> frame_memory_refusal(cv::Size frame_px) {
  const std::uint64_t bytes =
      std::uint64_t{3} * static_cast<std::uint64_t>(frame_px.width) * static_cast<std::uint64_t>(frame_px.height);
  const std::optional<std::string> beyond = io::beyond_available_memory(bytes);
  if (!beyond) return std::nullopt;
  return "a frame of " + std::to_string(frame_px.width) + "x" + std::to_string(frame_px.height) + " px needs at least " +
         io::gigabytes_text(bytes) + *beyond;
}

}  // namespace evlife::render
