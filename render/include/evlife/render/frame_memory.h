// Before drawing: a frame that would not fit in the memory available is
// refused with its size (`evlife render`, evlife.frame), instead of OpenCV's
// "Insufficient memory" or an OOM kill.
#pragma once

#include <opencv2/core/types.hpp>

#include <optional>
#include <string>

namespace evlife::render {

/// "a frame of WxH px needs at least G GB, more than the A GB of memory
/// available" when one drawn frame (3 bytes a pixel, the least a colour frame
/// and its encoding take) exceeds MemAvailable; nothing when it fits or the
/// memory available is unknown.
std::optional<std::string> frame_memory_refusal(cv::Size frame_px);

}  // namespace evlife::render
