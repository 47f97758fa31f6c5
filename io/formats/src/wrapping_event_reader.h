// Private: the base of the readers that wrap another reader (checked,
// cropping): all but read() is the inner reader's unless a wrapper overrides
// it. byte_offset_of_event is not passed on: a wrapper that drops events
// numbers them differently from its inner reader.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "evlife/io/event_reader.h"

namespace evlife::io::detail {

class WrappingEventReader : public EventReader {
 public:
  explicit WrappingEventReader(std::unique_ptr<EventReader> inner) : inner_(std::move(inner)) {}

  std::optional<SensorSize> sensor_size() const override { return inner_->sensor_size(); }
  std::string sensor_size_note() const override { return inner_->sensor_size_note(); }
  std::string_view format_name() const override { return inner_->format_name(); }
  const std::string& path() const override { return inner_->path(); }
  std::uint64_t skipped_record_count() const override { return inner_->skipped_record_count(); }
  std::uint64_t trigger_count() const override { return inner_->trigger_count(); }
  std::vector<SkippedKindCount> skipped_record_kinds() const override {
    return inner_->skipped_record_kinds();
  }
  std::vector<ContainerStream> streams() const override { return inner_->streams(); }
  std::uint64_t bytes_consumed() const override { return inner_->bytes_consumed(); }
  std::string clock_wrap_note() const override { return inner_->clock_wrap_note(); }
  std::string_view layout_name() const override { return inner_->layout_name(); }

 protected:
  std::unique_ptr<EventReader> inner_;
};

}  // namespace evlife::io::detail
