// Private: wraps any EventReader and turns coordinates outside the sensor and
// timestamps going backwards into ReadError — after delivering the good
// events before the fault (the EventReader contract).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>

#include "wrapping_event_reader.h"

namespace evlife::io::detail {

class CheckedEventReader final : public WrappingEventReader {
 public:
  /// `sensor`: bounds to check (nullopt: none); `require_time_order`: error
  /// when t decreases.
  CheckedEventReader(std::unique_ptr<EventReader> inner, std::optional<SensorSize> sensor,
                     bool require_time_order);

  std::size_t read(std::span<Event> out) override;
  std::optional<SensorSize> sensor_size() const override { return sensor_; }
  std::int64_t byte_offset_of_event(std::int64_t event_index) const override {
    return inner_->byte_offset_of_event(event_index);
  }
  /// The inner reader's; the events passed count in the indices of errors.
  std::int64_t skip_events_before(std::int64_t t_us) override;
  std::optional<std::int64_t> first_event_time_us() const override { return inner_->first_event_time_us(); }

 private:
  std::optional<SensorSize> sensor_;
  bool require_time_order_;
  std::int64_t delivered_ = 0;  // events returned so far
  std::int64_t last_t_us_ = INT64_MIN;
  std::optional<ReadError> pending_;  // thrown by the next read()
};

}  // namespace evlife::io::detail
