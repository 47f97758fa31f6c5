// The signals that ask a command to stop cleanly (finish the queued work,
// flush and close its output, exit 130): Ctrl-C (SIGINT), kill (SIGTERM) and
// a closed terminal or ssh session (SIGHUP), which otherwise killed the
// process with its output unclosed (an .h5 nothing opens). Installed for the
// lifetime of the object; the previous handlers come back after.
#pragma once

#include <csignal>

namespace evlife::cli {

class StopSignals {
 public:
  explicit StopSignals(void (*handler)(int)) noexcept
      : int_(std::signal(SIGINT, handler)), term_(std::signal(SIGTERM, handler)), hup_(std::signal(SIGHUP, handler)) {}
  ~StopSignals() {
    std::signal(SIGINT, int_);
    std::signal(SIGTERM, term_);
    std::signal(SIGHUP, hup_);
  }
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

 private:
  void (*int_)(int);
  void (*term_)(int);
  void (*hup_)(int);
};

}  // namespace evlife::cli
