// libevlife_media.so: image files, video files and windows with OpenCV's
// heavy modules, loaded on demand by render/src/media.cpp.
#include <cstdarg>
#include <exception>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/core/utils/logger.hpp>
#include <opencv2/highgui.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "../src/media_backend.h"

// FFmpeg's log (libavutil, loaded with OpenCV's video backend; weak: null
// where no FFmpeg is loaded). Declared here, not linked: the plugin builds
// where libavutil's headers are not installed.
extern "C" {
__attribute__((weak)) void av_log_set_callback(void (*callback)(void*, int, const char*, std::va_list));
__attribute__((weak)) void av_log_default_callback(void* avcl, int level, const char* fmt, std::va_list args);
}

namespace evlife::render::detail {
namespace {

// FFmpeg's log dropped while a check reads back a video that may be cut: its
// "moov atom not found" came before evlife's own message. (The level would
// not do: OpenCV sets it again at every open.)
class QuietFfmpeg {
 public:
  QuietFfmpeg() {
    if (quiet_) av_log_set_callback([](void*, int, const char*, std::va_list) {});
  }
  ~QuietFfmpeg() {
    if (quiet_) av_log_set_callback(av_log_default_callback);
  }
  QuietFfmpeg(const QuietFfmpeg&) = delete;
  QuietFfmpeg& operator=(const QuietFfmpeg&) = delete;

 private:
  const bool quiet_ = av_log_set_callback != nullptr && av_log_default_callback != nullptr;
};

class OpenCvVideo final : public VideoFile {
 public:
  bool open(const std::string& path, int fourcc, double fps, cv::Size frame_size) {
    path_ = path;
    // A failed open is evlife's own error to say (media.cpp: the path, the
    // codec, what to try). OpenCV's log of the backends it tried came first
    // ("[ERROR] ... raised OpenCV exception ... Assertion failed"), read as a crash.
    const auto level = cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
    const bool opened = writer_.open(path, fourcc, fps, frame_size, true);
    cv::utils::logging::setLogLevel(level);
    return opened;
  }
  void write(const cv::Mat& frame) override {
    writer_.write(frame);
    ++frames_;
  }
  // VideoWriter reports no write error: a full disk left an .mp4 without its
  // index (moov) that nothing plays, or an .avi cut short behind a complete
  // header. So the file is read back: it must open, count every frame written
  // and give the last one.
  void close() override {
    if (!writer_.isOpened()) return;
    writer_.release();
    if (frames_ == 0) return;
    bool complete = false;
    bool opened = false;
    {
      const QuietFfmpeg quiet;
      cv::VideoCapture check(path_, cv::CAP_FFMPEG);  // the backend that reads what the writer wrote
      opened = check.isOpened();
      const double counted = opened ? check.get(cv::CAP_PROP_FRAME_COUNT) : 0.0;
      complete = opened && counted >= static_cast<double>(frames_);
      if (complete) complete = check.set(cv::CAP_PROP_POS_FRAMES, static_cast<double>(frames_ - 1)) && check.grab();
    }
    if (!complete)
      throw std::runtime_error("the video " + path_ + " is incomplete: " + std::to_string(frames_) +
                               " frames written, " +
                               (opened ? "not all of them readable" : "the file does not open") +
                               " (disk full?)");
  }

 private:
  cv::VideoWriter writer_;
  std::string path_;
  long long frames_ = 0;
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
  bool encode_image(const std::string& extension, const cv::Mat& image, std::vector<unsigned char>& bytes) override {
    try {
      return cv::imencode(extension, image, bytes);
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

extern "C" __attribute__((visibility("default"))) evlife::render::detail::MediaBackend* evlife_media_backend_v2() {
  static evlife::render::detail::OpenCvBackend backend;
  return &backend;
}
