// The pixels that fire at hot-pixel rates over a run (>= kMinRateHz on
// average), counted event by event, for the summaries of `evlife process`,
// `info` and `run`: how many, the busiest one's rate and position, their
// share of the events and of theirs labelled noise.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "evlife/algo/event.h"

namespace evlife::cli {

class BusyPixels {
 public:
  /// A pixel is busy at this average rate: a hundred times the top of
  /// background activity (0.1-1 Hz per pixel), where hot pixels fire (tens
  /// of Hz to kHz: README, *Real background activity*).
  static constexpr double kMinRateHz = 100.0;
  /// Shorter recordings get no report: one edge's burst of a few events
  /// already makes a pixel's rate 100 Hz.
  static constexpr double kMinSpanS = 0.5;
  /// What busy pixels are, as the summaries say it: edges passing a pixel
  /// often fire that much too.
  static constexpr const char* kMeaning = "hot pixels, or edges passing that often";

  /// Counts nothing without a sensor size or for a side beyond
  /// kMaxSensorSide; else 8 bytes a pixel.
  explicit BusyPixels(std::optional<SensorSize> sensor);

  void add(const AugmentedEvent& a) noexcept {
    if (pixel_events_.empty() || a.event.x >= sensor_.width || a.event.y >= sensor_.height) return;
    const std::size_t i = static_cast<std::size_t>(a.event.y) * static_cast<std::size_t>(sensor_.width) + a.event.x;
    pixel_events_[i] += pixel_events_[i] != UINT32_MAX;  // saturates
    pixel_noise_[i] += a.is_noise() && pixel_noise_[i] != UINT32_MAX;
  }

  struct Report {
    std::uint64_t pixels = 0;  // at >= kMinRateHz
    /// "40 of 76800 (busiest 1.1 kHz at (187, 105)): 8.0 % of the events,
    /// 95.6 % of theirs labelled noise", or "none of 16384 (busiest 51.8 Hz
    /// at (62, 29))".
    std::string text;
  };
  /// Over `span_s` seconds and `events` in all; none without a sensor size,
  /// without an event inside it or under kMinSpanS.
  std::optional<Report> report(double span_s, std::uint64_t events) const;

 private:
  SensorSize sensor_{0, 0};
  std::vector<std::uint32_t> pixel_events_;  // [y * width + x], both polarities
  std::vector<std::uint32_t> pixel_noise_;   // of them labelled noise
};

}  // namespace evlife::cli
