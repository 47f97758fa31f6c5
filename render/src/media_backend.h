// Private: the interface between render/media.cpp and the plugin
// libevlife_media.so (render/media_plugin/), which implements it with
// OpenCV's imgcodecs, videoio and highgui. Versioned by the entry point's name
// (v2: images encoded, not written, by the plugin).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "evlife/render/media.h"

namespace evlife::render::detail {

class MediaBackend {
 public:
  virtual ~MediaBackend() = default;
  /// The image file's bytes in the format of `extension` (".png"); false when
  /// it cannot be encoded. The file is written by media.cpp, which checks
  /// every write: imwrite's stdio close, where a full disk's last buffer
  /// fails, goes unchecked.
  virtual bool encode_image(const std::string& extension, const cv::Mat& image, std::vector<unsigned char>& bytes) = 0;
  virtual cv::Mat read_image(const std::string& path) = 0;
  /// nullptr when the file cannot be opened for writing.
  virtual std::unique_ptr<VideoFile> open_video(const std::string& path, double fps, cv::Size frame_size) = 0;
  virtual std::unique_ptr<Window> open_window(const std::string& title) = 0;
};

}  // namespace evlife::render::detail

// The plugin's one exported symbol.
#define EVLIFE_MEDIA_ENTRY_POINT "evlife_media_backend_v2"
extern "C" evlife::render::detail::MediaBackend* evlife_media_backend_v2();
