// libevlife_media.so: image files, video files and windows with OpenCV's
// heavy modules, loaded on demand by render/src/media.cpp.
#include <exception>
#include <string>

#include <opencv2/highgui.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "../src/media_backend.h"

namespace evlife::render::detail {
namespace {

class OpenCvVideo final : public VideoFile {
 public:
  bool open(const std::string& path, int fourcc, double fps, cv::Size frame_size) {
    return writer_.open(path, fourcc, fps, frame_size, true);
  }
  void write(const cv::Mat& frame) override { writer_.write(frame); }
  void close() override { writer_.release(); }

 private:
  cv::VideoWriter writer_;
};

class OpenCvWindow final : public Window {
 public:
  explicit OpenCvWindow(std::string title) : title_(std::move(title)) {
    cv::namedWindow(title_, cv::WINDOW_AUTOSIZE);
  }
  ~OpenCvWindow() override {
    try {
      close();
    } catch (...) {  // a destructor must not throw; the window goes with the process
    }
  }
  bool show(const cv::Mat& frame) override {
    cv::imshow(title_, frame);
    const int key = cv::waitKey(1);  // also lets the toolkit draw and handle events
    const bool quit_key = key == 'q' || key == 'Q' || key == 27;
    return !quit_key && cv::getWindowProperty(title_, cv::WND_PROP_VISIBLE) >= 1.0;
  }
  void close() override {
    if (closed_) return;
    closed_ = true;
    cv::destroyWindow(title_);
    cv::waitKey(1);
  }

 private:
  std::string title_;
  bool closed_ = false;
};

class OpenCvBackend final : public MediaBackend {
 public:
  bool write_image(const std::string& path, const cv::Mat& image) override {
    try {
      return cv::imwrite(path, image);
    } catch (const cv::Exception&) {
      return false;
    }
  }
  cv::Mat read_image(const std::string& path) override { return cv::imread(path, cv::IMREAD_COLOR); }
  std::unique_ptr<VideoFile> open_video(const std::string& path, double fps, cv::Size frame_size) override {
    const char* c = video_codec(path);
    const int fourcc = cv::VideoWriter::fourcc(c[0], c[1], c[2], c[3]);
    auto video = std::make_unique<OpenCvVideo>();
    if (!video->open(path, fourcc, fps, frame_size)) return nullptr;
    return video;
  }
  std::unique_ptr<Window> open_window(const std::string& title) override {
    return std::make_unique<OpenCvWindow>(title);
  }
};

}  // namespace
}  // namespace evlife::render::detail

extern "C" __attribute__((visibility("default"))) evlife::render::detail::MediaBackend* evlife_media_backend_v1() {
  static evlife::render::detail::OpenCvBackend backend;
  return &backend;
}
