// What a run produced, accumulated batch by batch in memory fixed at the
// start and printed at the end: events, share labelled noise, lifetime
// percentiles, prediction coverage and error, speed, and (with the sensor
// size) the pixels that fire at hot-pixel rates. Shared by commands that
// estimate.
#pragma once

#include <cstdint>
#include <cstdio>
#include <optional>
#include <span>
#include <string>

#include "busy_pixels.h"
#include "evlife/algo/event.h"
#include "evlife/render/histogram.h"

namespace evlife::cli {

class LifetimeSummary {
 public:
  /// With a sensor size, also counts events per pixel (8 bytes a pixel) for
  /// the line on pixels firing at hot-pixel rates.
  explicit LifetimeSummary(std::optional<SensorSize> sensor = std::nullopt);

  void add(std::span<const AugmentedEvent> events) noexcept;

  std::uint64_t events() const noexcept { return events_; }
  std::uint64_t noise() const noexcept { return noise_; }
  std::uint64_t predictions() const noexcept { return predictions_; }
  const render::Histogram& lifetime_us() const noexcept { return lifetime_us_; }
  const render::Histogram& abs_prediction_error_us() const noexcept { return abs_error_us_; }

  /// Multi-line report; `wall_s` is the run's wall time, `estimator_s` the
  /// time spent inside the estimator (both in seconds).
  void print(std::FILE* out, double wall_s, double estimator_s) const;
  /// The same report from "labelled noise" on, without the timing line: for
  /// a file estimated earlier, whose events a caller has described.
  void print_figures(std::FILE* out) const;

 private:
  void print_lifetimes(std::FILE* out) const;  // labelled noise .. prediction error
  void print_notes(std::FILE* out) const;      // percentile precision, warm-up, busy pixels
  std::uint64_t events_ = 0;
  std::uint64_t noise_ = 0;
  std::uint64_t predictions_ = 0;
  std::int64_t first_t_us_ = 0;
  std::int64_t last_t_us_ = 0;
  render::Histogram lifetime_us_;
  render::Histogram abs_error_us_;
  BusyPixels busy_pixels_;
};

/// The recording's time range as every summary states it:
/// "t = 0 .. 2345678 us (2.345678 s long)".
std::string format_time_range(std::int64_t first_t_us, std::int64_t last_t_us);
/// "850 µs", "12.3 ms", "1.52 s": a duration given in microseconds.
std::string format_duration_us(double us);
/// "1.23 M", "456 k": a count or rate with an SI prefix.
std::string format_si(double value);

}  // namespace evlife::cli
