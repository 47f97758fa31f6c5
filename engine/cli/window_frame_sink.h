// `evlife run --window`: the render thread's frames in an on-screen window
// (render/media.h: the GUI toolkit is loaded only when a window opens).
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "evlife/render/frame_sink.h"
#include "evlife/render/media.h"

namespace evlife::cli {

/// Empty when a window can be opened here; else why not, naming the display.
/// highgui's toolkit aborts the process when the display cannot be reached,
/// so the first window is tried in a forked child. Call before any thread
/// starts.
std::string probe_window_display();

class WindowFrameSink final : public render::FrameSink {
 public:
  /// `on_close` runs (on the render thread) when the user closes the window
  /// or presses q / Esc in it: the run then stops as on SIGINT.
  WindowFrameSink(std::string title, std::function<void()> on_close);
  ~WindowFrameSink() override;

  void write(const render::FrameImage& frame, std::int64_t t_us) override;
  void finish() override;

 private:
  std::string title_;
  std::function<void()> on_close_;
  std::unique_ptr<render::Window> window_;
  bool closed_by_user_ = false;
};

}  // namespace evlife::cli
