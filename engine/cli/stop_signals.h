// The signals that ask a command to stop cleanly (finish the queued work,
// flush and close its output, exit 130): Ctrl-C (SIGINT), kill (SIGTERM) and
// a closed terminal or ssh session (SIGHUP), which otherwise killed the
// process with its output unclosed (an .h5 nothing opens). Installed for the
// lifetime of the object; the previous handlers come back after.
#pragma once

#include <signal.h>

#include <array>
#include <atomic>

namespace evlife::cli {

class StopSignals {
 public:
  /// `interrupt_calls`: a blocking system call the signal lands in fails
  /// with EINTR instead of restarting (a read waiting on a stalled pipe).
  explicit StopSignals(void (*handler)(int), bool interrupt_calls = false) noexcept {
    struct sigaction sa {};
    sa.sa_handler = handler;
    sa.sa_flags = interrupt_calls ? 0 : SA_RESTART;
    sigemptyset(&sa.sa_mask);
    for (std::size_t i = 0; i < kSignals.size(); ++i) sigaction(kSignals[i], &sa, &old_[i]);
  }
  ~StopSignals() {
    for (std::size_t i = 0; i < kSignals.size(); ++i) sigaction(kSignals[i], &old_[i], nullptr);
  }
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

 private:
  static constexpr std::array<int, 3> kSignals{SIGINT, SIGTERM, SIGHUP};
  std::array<struct sigaction, 3> old_{};
};

/// The stop flag of the commands that poll one (process, render, eval,
/// synth, the copy of a stream): cleared when a StopRequest starts, set by
/// the signals while it lives. One command runs per process, so one flag.
inline std::atomic<bool> g_stop_requested{false};
static_assert(std::atomic<bool>::is_always_lock_free);  // async-signal-safe
extern "C" inline void evlife_cli_on_stop_signal(int) { g_stop_requested.store(true); }

class StopRequest {
 public:
  explicit StopRequest(bool interrupt_calls = false) noexcept
      : signals_((g_stop_requested.store(false), evlife_cli_on_stop_signal), interrupt_calls) {}
  bool requested() const noexcept { return g_stop_requested.load(std::memory_order_relaxed); }
  /// For the loops that take the flag itself.
  const std::atomic<bool>* flag() const noexcept { return &g_stop_requested; }

 private:
  StopSignals signals_;
};

}  // namespace evlife::cli
