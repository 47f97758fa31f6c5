// Image files, video files and on-screen windows. The OpenCV modules behind
// them (imgcodecs, videoio, highgui) load ~240 shared libraries (GDAL,
// FFmpeg, GStreamer, GTK): they live in a plugin, libevlife_media.so, that is
// loaded on the first call here, so a command that draws nothing (`evlife
// process`, `--help`) starts without them. Every function throws
// std::runtime_error naming the file (or the plugin, when it cannot be
// loaded); none is for a real-time path.
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include <opencv2/core.hpp>

#include "evlife/render/frame_sink.h"
#include "evlife/render/output_kind.h"

namespace evlife::render {

/// A frame as a plain image (no copy; valid while `image`, CV_8UC3, is).
inline FrameImage as_frame(const cv::Mat& image) {
  return {image.data, image.cols, image.rows, image.step[0]};
}
/// A plain image as a Mat header (no copy).
inline cv::Mat as_mat(const FrameImage& frame) {
  return cv::Mat(frame.height, frame.width, CV_8UC3, const_cast<std::uint8_t*>(frame.bgr),
                 frame.stride_bytes);
}

/// Writes `image` (CV_8UC3 or CV_8UC1; format from the extension, e.g. .png).
void write_image(const std::string& path, const cv::Mat& image);

/// Reads an image file as CV_8UC3; an empty Mat when it cannot be read.
cv::Mat read_image(const std::string& path);

class VideoFile {
 public:
  virtual ~VideoFile() = default;
  virtual void write(const cv::Mat& frame) = 0;  ///< frames of the size given at open
  virtual void close() = 0;                      ///< flushes; idempotent

 protected:
  VideoFile() = default;
  VideoFile(const VideoFile&) = default;
  VideoFile& operator=(const VideoFile&) = default;
};

/// A video file played at `fps`, codec video_codec(path). Throws
/// std::runtime_error naming the file and the codec.
std::unique_ptr<VideoFile> open_video(const std::string& path, double fps, cv::Size frame_size);

class Window {
 public:
  virtual ~Window() = default;
  /// Shows `frame`, handles the toolkit's events; false once the user closed
  /// the window or pressed q / Esc.
  virtual bool show(const cv::Mat& frame) = 0;
  virtual void close() = 0;  ///< idempotent

 protected:
  Window() = default;
  Window(const Window&) = default;
  Window& operator=(const Window&) = default;
};

/// An on-screen window (needs a display; see engine/cli/window_frame_sink.h
/// for the probe that makes a missing one an error, not an abort).
std::unique_ptr<Window> open_window(const std::string& title);

/// Opens and closes a window at once, in this process (the probe runs it in
/// a child: the toolkit aborts when the display cannot be reached).
void try_window();

}  // namespace evlife::render
