#include "evlife/render/frame_sink.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <system_error>

#include "evlife/io/output_path.h"
#include "evlife/render/media.h"

namespace evlife::render {

PngFolderFrameSink::PngFolderFrameSink(std::string dir, const std::string& input) : dir_(std::move(dir)) {
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (ec || !std::filesystem::is_directory(dir_)) {
    throw std::runtime_error("cannot create directory " + dir_ + ": " +
                             (ec ? ec.message() : std::string("not a directory")));
  }
  for (const auto& entry : std::filesystem::directory_iterator(dir_, ec)) {
    const std::string name = entry.path().filename().string();
    if (!name.starts_with("frame_") || !name.ends_with(".png")) continue;
    if (!input.empty()) {
      if (const auto refusal = io::output_overwrites_input(input, entry.path().string())) {
        throw std::runtime_error(*refusal + " (it has a frame's name in the frames' folder)");
      }
    }
    earlier_.insert(name);
  }
}

std::string PngFolderFrameSink::file_name(long long index, std::int64_t t_us) {
  char name[80];
  std::snprintf(name, sizeof name, "frame_%06lld_t%.6fs.png", index, static_cast<double>(t_us) * 1e-6);
  return name;
}

void PngFolderFrameSink::write(const FrameImage& frame, std::int64_t t_us) {
  const std::string name = file_name(index_++, t_us);
  if (!earlier_.empty()) earlier_.erase(name);
  write_image((std::filesystem::path(dir_) / name).string(), as_mat(frame));
}

ImageFileFrameSink::ImageFileFrameSink(std::string path) : path_(std::move(path)) {
  if (const std::string problem = io::create_output_folders(path_); !problem.empty())
    throw std::runtime_error(path_ + ": " + problem);
}

void ImageFileFrameSink::write(const FrameImage& frame, std::int64_t) { write_image(path_, as_mat(frame)); }

VideoFrameSize video_frame_size(int width, int height) {
  const auto side = [](int n) { return std::max(kMinVideoSidePx, n + (n & 1)); };
  return {side(width), side(height)};
}

VideoFrameSink::VideoFrameSink(std::string path, double playback_fps)
    : path_(std::move(path)), playback_fps_(playback_fps) {
  if (const std::string problem = io::create_output_folders(path_); !problem.empty())
    throw std::runtime_error(path_ + ": " + problem);
  // A pipe or a device: the encoder's writes to it fail unreported (a reader
  // that left), and the check of the finished file (its reading back) would
  // wait for ever on a FIFO, deaf to Ctrl-C.
  if (const auto problem =
          io::seekable_output_problem(path_, "a video's container is completed by seeking back into it and then read back")) {
    throw std::runtime_error(path_ + ": " + *problem);
  }
}

VideoFrameSink::~VideoFrameSink() = default;

void VideoFrameSink::check(int width, int height) const {
  const std::filesystem::path out(path_);
  const std::filesystem::path probe =
      out.parent_path() / (".evlife-probe-" + std::to_string(::getpid()) + out.extension().string());
  std::error_code ec;
  try {
    const VideoFrameSize size = video_frame_size(width, height);
    open_video(probe.string(), playback_fps_, cv::Size(size.width, size.height))->close();
  } catch (const std::runtime_error& e) {
    std::filesystem::remove(probe, ec);
    std::string message = e.what();  // said of the output, not of the probe
    for (auto at = message.find(probe.string()); at != std::string::npos; at = message.find(probe.string()))
      message.replace(at, probe.string().size(), path_);
    throw std::runtime_error(message);
  }
  std::filesystem::remove(probe, ec);
}

void VideoFrameSink::write(const FrameImage& frame, std::int64_t) {
  const VideoFrameSize size = video_frame_size(frame.width, frame.height);
  if (!video_) video_ = open_video(path_, playback_fps_, cv::Size(size.width, size.height));
  if (size == VideoFrameSize{frame.width, frame.height}) {
    video_->write(as_mat(frame));
    return;
  }
  const std::size_t stride = static_cast<std::size_t>(size.width) * 3;
  padded_.assign(stride * static_cast<std::size_t>(size.height), 0);
  for (int y = 0; y < frame.height; ++y) {
    std::memcpy(padded_.data() + static_cast<std::size_t>(y) * stride,
                frame.bgr + static_cast<std::size_t>(y) * frame.stride_bytes, static_cast<std::size_t>(frame.width) * 3);
  }
  video_->write(as_mat(FrameImage{padded_.data(), size.width, size.height, stride}));
}

void VideoFrameSink::finish() {
  if (video_) video_->close();
}

}  // namespace evlife::render
