// Where drawn frames go: numbered PNG files in a folder, one PNG file, or a
// video file (an on-screen window: engine/cli/window_frame_sink.h). A frame
// is a plain image (FrameImage, no OpenCV in this header), so the engine's
// render stage and the command line hand frames to the same sinks. Called
// from one thread; write() may throw std::runtime_error naming the file.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace evlife::render {

class VideoFile;

/// A view of an 8-bit BGR image (3 bytes a pixel), rows `stride_bytes` apart.
struct FrameImage {
  const std::uint8_t* bgr = nullptr;
  int width = 0;
  int height = 0;
  std::size_t stride_bytes = 0;
};

class FrameSink {
 public:
  virtual ~FrameSink() = default;
  /// `t_us` names the frame (file sinks put it into the file name).
  virtual void write(const FrameImage& frame, std::int64_t t_us) = 0;
  virtual void finish() {}
  /// Files of an earlier run that this one's output sits beside and did not
  /// replace (a frame folder used twice): a video made of the folder would
  /// mix them in. 0 for sinks that write one file.
  virtual std::size_t earlier_frames_left() const { return 0; }

 protected:
  FrameSink() = default;
  FrameSink(const FrameSink&) = default;
  FrameSink& operator=(const FrameSink&) = default;
};

/// DIR/frame_000000_t0.500000s.png, ...: frame number and time from the
/// stream's first event in seconds (the unit the flags take); `evlife render
/// -o DIR` and `evlife run --frames DIR` name frames alike. Creates DIR (and
/// its parents). Throws std::runtime_error naming the folder or file that
/// cannot be written.
class PngFolderFrameSink final : public FrameSink {
 public:
  /// Throws std::runtime_error when the folder cannot be made, or holds
  /// `input` (the recording drawn; through any link) under a frame's name: a
  /// frame drawn there would overwrite it.
  explicit PngFolderFrameSink(std::string dir, const std::string& input = {});
  void write(const FrameImage& frame, std::int64_t t_us) override;
  /// frame_*.png files the folder held before that this run did not write.
  std::size_t earlier_frames_left() const override { return earlier_.size(); }
  /// The file name of frame number `index` at `t_us` from the first event.
  static std::string file_name(long long index, std::int64_t t_us);

 private:
  std::string dir_;
  long long index_ = 0;
  std::set<std::string> earlier_;  // frame files found at the start, not written since
};

/// Every frame to one image file (FILE.png: the frame of one instant).
/// Creates the parent folders.
class ImageFileFrameSink final : public FrameSink {
 public:
  explicit ImageFileFrameSink(std::string path);
  void write(const FrameImage& frame, std::int64_t t_us) override;

 private:
  std::string path_;
};

/// The size a video encodes a width x height frame at: padded with black on
/// the right and at the bottom to even sides of at least kMinVideoSidePx.
/// Encoders need even sides (an odd one lost its last column or row) and
/// libswscale wrote past its buffers on frames a few pixels wide.
inline constexpr int kMinVideoSidePx = 16;
struct VideoFrameSize {
  int width = 0;
  int height = 0;
  bool operator==(const VideoFrameSize&) const = default;
};
VideoFrameSize video_frame_size(int width, int height);

/// A video (.mp4: codec mp4v, else MJPG; render/media.h) played at
/// `playback_fps`; opened by open() or at the first frame (its size). Creates
/// the parent folders. Throws std::runtime_error naming the file and codec.
class VideoFrameSink final : public FrameSink {
 public:
  VideoFrameSink(std::string path, double playback_fps);
  ~VideoFrameSink() override;
  /// Reports a missing encoder or an unwritable folder before any frame is
  /// drawn, by opening and removing a video beside the output: the output
  /// itself (an earlier video of that name) is replaced only by the first
  /// frame written. Throws std::runtime_error naming the output.
  void check(int width, int height) const;
  void write(const FrameImage& frame, std::int64_t t_us) override;
  void finish() override;

 private:
  std::string path_;
  double playback_fps_;
  std::unique_ptr<VideoFile> video_;
  std::vector<std::uint8_t> padded_;  // a frame padded to video_frame_size(), reused
};

}  // namespace evlife::render
