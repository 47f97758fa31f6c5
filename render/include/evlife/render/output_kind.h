// What a rendered output's path names, from its extension: one rule for
// `evlife render -o` and `evlife run --video` (and the video codec it picks).
#pragma once

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>
#include <string_view>

namespace evlife::render {

enum class OutputKind {
  frames_folder,  ///< no image or video extension: a folder of PNG frames
  single_png,     ///< FILE.png: one frame
  video,          ///< .mp4 (mp4v) or .avi (MJPG)
  unsupported,    ///< an image or video format OpenCV may lack or would misname
};

/// The path's extension in lower case (".MP4" names a video as ".mp4" does).
inline std::string lowercase_extension(std::string_view path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

inline OutputKind output_kind(std::string_view path) {
  const std::string ext = lowercase_extension(path);
  if (ext == ".mp4" || ext == ".avi") return OutputKind::video;
  if (ext == ".png") return OutputKind::single_png;
  for (const char* other : {".jpg", ".jpeg", ".gif", ".bmp", ".tif", ".tiff", ".mkv", ".mov", ".webm", ".avif"}) {
    if (ext == other) return OutputKind::unsupported;
  }
  return OutputKind::frames_folder;
}

/// The codec of a video file (OutputKind::video): "mp4v" for .mp4, else "MJPG".
inline const char* video_codec(std::string_view path) {
  return lowercase_extension(path) == ".mp4" ? "mp4v" : "MJPG";
}

}  // namespace evlife::render
