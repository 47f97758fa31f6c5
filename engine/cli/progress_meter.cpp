#include "progress_meter.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "lifetime_summary.h"  // format_si

namespace evlife::cli {
namespace {
constexpr auto kTtyInterval = std::chrono::milliseconds(250);
constexpr auto kLogInterval = std::chrono::seconds(10);
}  // namespace

ProgressMeter::ProgressMeter(std::string label, std::int64_t total_bytes,
                             std::function<std::int64_t()> bytes_done)
    : label_(std::move(label)),
      total_bytes_(total_bytes),
      bytes_done_(std::move(bytes_done)),
      tty_(isatty(STDERR_FILENO) == 1),
      start_(Clock::now()),
      next_(start_ + (tty_ ? std::chrono::milliseconds(500) : kLogInterval)) {}

void ProgressMeter::update(std::uint64_t events) {
  if (!enabled_) return;
  const auto now = Clock::now();
  if (now < next_) return;
  next_ = now + (tty_ ? kTtyInterval : kLogInterval);

  const double elapsed_s = std::chrono::duration<double>(now - start_).count();
  const double rate = elapsed_s > 0 ? static_cast<double>(events) / elapsed_s : 0.0;
  std::string line = label_ + ": ";
  char buf[128];
  const std::int64_t done = bytes_done_ ? bytes_done_() : -1;
  if (total_bytes_ > 0 && done > 0) {
    const double frac = std::min(1.0, static_cast<double>(done) / static_cast<double>(total_bytes_));
    std::snprintf(buf, sizeof buf, "%5.1f %% of %sB, ", 100.0 * frac,
                  format_si(static_cast<double>(total_bytes_)).c_str());
    line += buf;
    if (frac > 0.0) {
      const double eta_s = elapsed_s * (1.0 - frac) / frac;
      std::snprintf(buf, sizeof buf, "ETA %.0f s, ", eta_s);
      line += buf;
    }
  }
  std::snprintf(buf, sizeof buf, "%sevents, %sevents/s", format_si(static_cast<double>(events)).c_str(),
                format_si(rate).c_str());
  line += buf;
  if (tty_) {
    std::fprintf(stderr, "\r\033[K%s", line.c_str());
  } else {
    std::fprintf(stderr, "%s\n", line.c_str());
  }
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressMeter::finish() {
  if (tty_ && drawn_) {
    std::fprintf(stderr, "\r\033[K");
    std::fflush(stderr);
  }
  drawn_ = false;
}

}  // namespace evlife::cli
