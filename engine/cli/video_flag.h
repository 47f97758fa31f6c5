// `--video FILE` of `evlife run` and `evlife render`: the refusal of a name
// that is no video's (render::output_kind()).
#pragma once

#include <string>

namespace evlife::cli {

inline std::string video_flag_refusal(const std::string& path) {
  return "--video " + path + ": the video must end in .mp4 or .avi (--frames DIR for PNG frames)";
}

}  // namespace evlife::cli
