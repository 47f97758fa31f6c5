#include "checked_event_reader.h"

#include <utility>

namespace evlife::io::detail {

CheckedEventReader::CheckedEventReader(std::unique_ptr<EventReader> inner,
                                       std::optional<SensorSize> sensor,
                                       bool require_time_order)
    : WrappingEventReader(std::move(inner)), sensor_(sensor), require_time_order_(require_time_order) {}

std::int64_t CheckedEventReader::skip_events_before(std::int64_t t_us) {
  if (delivered_ != 0 || pending_) return 0;
  delivered_ = inner_->skip_events_before(t_us);
  return delivered_;
}

std::size_t CheckedEventReader::read(std::span<Event> out) {
  if (pending_) throw *pending_;
  const std::size_t n = inner_->read(out);
  // Sentinel values make the common case one branch per check.
  const int width = sensor_ ? sensor_->width : 1 << 30;
  const int height = sensor_ ? sensor_->height : 1 << 30;
  std::int64_t last = last_t_us_;
  std::size_t i = 0;
  for (; i < n; ++i) {
    const Event& e = out[i];
    if (e.x >= width || e.y >= height) break;
    if (require_time_order_ && e.t_us < last) break;
    last = e.t_us;
  }
  if (i < n) {
    const Event& e = out[i];
    const std::int64_t index = delivered_ + static_cast<std::int64_t>(i);
    std::string what;
    if (e.x >= width || e.y >= height) {
      what = "event at (x " + std::to_string(e.x) + ", y " + std::to_string(e.y) +
             ") is outside the " + std::to_string(width) + "x" + std::to_string(height) +
             " sensor";
    } else {
      what = "timestamp goes backwards: " + std::to_string(e.t_us) + " us after " +
             std::to_string(last) + " us";
      if (const std::string note = inner_->clock_wrap_note(); !note.empty()) what += " (" + note + ")";
    }
    pending_.emplace(inner_->path(), inner_->byte_offset_of_event(index), index, what);
    if (i == 0) throw *pending_;  // 0 would mean "end of stream"
  }
  last_t_us_ = last;
  delivered_ += static_cast<std::int64_t>(i);
  return i;
}

}  // namespace evlife::io::detail
