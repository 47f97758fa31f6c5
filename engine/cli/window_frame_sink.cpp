#include "window_frame_sink.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <thread>

#include "evlife/render/media.h"

namespace evlife::cli {

std::string probe_window_display() {
  const char* x11 = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  const bool has_x11 = x11 != nullptr && *x11 != '\0';
  const bool has_wayland = wayland != nullptr && *wayland != '\0';
  if (!has_x11 && !has_wayland)
    return "--window needs a display, and neither DISPLAY nor WAYLAND_DISPLAY is set "
           "(use --frames DIR or --video FILE, or run under xvfb-run)";
  const std::string which = has_x11 ? "DISPLAY=" + std::string(x11)
                                    : "WAYLAND_DISPLAY=" + std::string(wayland);
  const pid_t child = fork();
  if (child < 0) return "--window: cannot test the display " + which + " (fork failed)";
  if (child == 0) {
    // The toolkit prints its own complaints; the parent says what matters.
    const int null_fd = open("/dev/null", O_WRONLY);
    if (null_fd >= 0) {
      dup2(null_fd, STDERR_FILENO);
      dup2(null_fd, STDOUT_FILENO);
    }
    try {
      render::try_window();
    } catch (...) {
      _exit(1);
    }
    _exit(0);
  }
  // A display that does not answer can hang the toolkit: give it 10 s.
  int status = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (waitpid(child, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      kill(child, SIGKILL);
      waitpid(child, &status, 0);
      return "--window: the display " + which + " did not answer within 10 s";
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return {};
  return "--window: cannot open a window on " + which +
         " (the GUI toolkit failed; use --frames DIR or --video FILE)";
}

WindowFrameSink::WindowFrameSink(std::string title, std::function<void()> on_close)
    : title_(std::move(title)), on_close_(std::move(on_close)) {}

WindowFrameSink::~WindowFrameSink() {
  try {
    finish();
  } catch (...) {  // a destructor must not throw; the window is gone with the process
  }
}

void WindowFrameSink::write(const render::FrameImage& frame, std::int64_t /*t_us*/) {
  if (closed_by_user_) return;  // the run is stopping; frames still count
  if (!window_) window_ = render::open_window(title_);
  if (!window_->show(render::as_mat(frame))) {
    closed_by_user_ = true;
    if (on_close_) on_close_();
  }
}

void WindowFrameSink::finish() {
  if (window_) window_->close();
}

}  // namespace evlife::cli
