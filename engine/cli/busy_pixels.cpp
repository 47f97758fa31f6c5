#include "busy_pixels.h"

#include <cstdio>

#include "lifetime_summary.h"

namespace evlife::cli {

BusyPixels::BusyPixels(std::optional<SensorSize> sensor) {
  // A file may state (or its events span) a larger sensor than any camera:
  // no counts then, rather than gigabytes.
  if (sensor && sensor->within_camera_limits()) {
    sensor_ = *sensor;
    pixel_events_.assign(static_cast<std::size_t>(sensor->pixel_count()), 0);
    pixel_noise_.assign(pixel_events_.size(), 0);
  }
}

std::optional<BusyPixels::Report> BusyPixels::report(double span_s, std::uint64_t events) const {
  if (pixel_events_.empty() || !(span_s >= kMinSpanS) || events == 0) return std::nullopt;
  std::uint64_t busy = 0, busy_events = 0, busy_noise = 0;
  std::size_t busiest = 0;
  for (std::size_t i = 0; i < pixel_events_.size(); ++i) {
    if (pixel_events_[i] > pixel_events_[busiest]) busiest = i;
    if (static_cast<double>(pixel_events_[i]) >= kMinRateHz * span_s) {
      ++busy;
      busy_events += pixel_events_[i];
      busy_noise += pixel_noise_[i];
    }
  }
  if (pixel_events_[busiest] == 0) return std::nullopt;  // every event outside the sensor
  const auto width = static_cast<std::size_t>(sensor_.width);
  char text[256];
  const int n = std::snprintf(text, sizeof text, "%s of %zu (busiest %sHz at (%zu, %zu))",
                              busy == 0 ? "none" : std::to_string(busy).c_str(), pixel_events_.size(),
                              format_si(static_cast<double>(pixel_events_[busiest]) / span_s).c_str(),
                              busiest % width, busiest / width);
  if (busy > 0 && n > 0 && static_cast<std::size_t>(n) < sizeof text) {
    std::snprintf(text + n, sizeof text - static_cast<std::size_t>(n),
                  ": %.1f %% of the events, %.1f %% of theirs labelled noise",
                  100.0 * static_cast<double>(busy_events) / static_cast<double>(events),
                  100.0 * static_cast<double>(busy_noise) / static_cast<double>(busy_events));
  }
  return Report{busy, text};
}

}  // namespace evlife::cli
