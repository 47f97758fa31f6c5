// Where rendered frames go: numbered PNG files in a folder, or a video file.
// Called from the render thread only; may throw (a file boundary).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include <opencv2/core.hpp>

namespace evlife::render {
class VideoFile;
}

namespace evlife::engine {

class FrameSink {
 public:
  virtual ~FrameSink() = default;
  /// `t_us`: the frame's instant from the stream's first event (RenderStage).
  virtual void write(const cv::Mat& frame, std::int64_t t_us) = 0;
  virtual void finish() {}

 protected:
  FrameSink() = default;
  FrameSink(const FrameSink&) = default;
  FrameSink& operator=(const FrameSink&) = default;
};

/// DIR/frame_000000_t0.250000s.png, ... (render::frame_file_name, as `evlife render`). Creates DIR. Throws std::runtime_error
/// naming the file when one cannot be written.
class PngFolderFrameSink final : public FrameSink {
 public:
  explicit PngFolderFrameSink(std::string dir);
  void write(const cv::Mat& frame, std::int64_t t_us) override;

 private:
  std::string dir_;
  long long index_ = 0;
};

/// A video (.mp4: mp4v, else MJPG) played at `playback_fps`; opened at the
/// first frame (its size). Throws std::runtime_error naming the file.
class VideoFrameSink final : public FrameSink {
 public:
  VideoFrameSink(std::string path, double playback_fps);
  ~VideoFrameSink() override;
  void write(const cv::Mat& frame, std::int64_t t_us) override;
  void finish() override;

 private:
  std::string path_;
  double playback_fps_;
  std::unique_ptr<render::VideoFile> video_;  // opened at the first frame
};

}  // namespace evlife::engine
