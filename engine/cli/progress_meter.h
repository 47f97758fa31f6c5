// Progress of a long run on stderr: share done, events, rate, ETA. On a
// terminal it redraws one line a few times per second; otherwise (CI logs,
// pipes) it prints a plain line every 10 s, so short runs print nothing.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>

namespace evlife::cli {

class ProgressMeter {
 public:
  /// `bytes_done` reports how far through `total_bytes` the run is (<= 0:
  /// unknown yet); total_bytes <= 0 hides the percentage and ETA.
  ProgressMeter(std::string label, std::int64_t total_bytes,
                std::function<std::int64_t()> bytes_done);

  /// Call after each batch; prints only when a line is due.
  void update(std::uint64_t events);
  /// Clears the terminal line (call before printing anything else).
  void finish();

  void set_enabled(bool enabled) { enabled_ = enabled; }

 private:
  using Clock = std::chrono::steady_clock;
  std::string label_;
  std::int64_t total_bytes_;
  std::function<std::int64_t()> bytes_done_;
  bool tty_;
  bool enabled_ = true;
  bool drawn_ = false;
  Clock::time_point start_;
  Clock::time_point next_;
};

}  // namespace evlife::cli
