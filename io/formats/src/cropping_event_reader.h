// Private: applies ReaderOptions' cropping (--from/--to, relative to the
// first event of the file) and polarity filter to any reader. Errors of the
// inner reader pass through after the kept events before them.
#pragma once

#include <memory>

#include "evlife/io/event_reader.h"

namespace evlife::io::detail {

class CroppingEventReader final : public EventReader {
 public:
  CroppingEventReader(std::unique_ptr<EventReader> inner, const ReaderOptions& options);

  std::size_t read(std::span<Event> out) override;
  std::optional<SensorSize> sensor_size() const override { return inner_->sensor_size(); }
  std::string_view format_name() const override { return inner_->format_name(); }
  const std::string& path() const override { return inner_->path(); }
  std::uint64_t skipped_record_count() const override { return inner_->skipped_record_count(); }
  std::uint64_t trigger_count() const override { return inner_->trigger_count(); }
  std::vector<SkippedKindCount> skipped_record_kinds() const override {
    return inner_->skipped_record_kinds();
  }
  std::vector<ContainerStream> streams() const override { return inner_->streams(); }
  std::uint64_t bytes_consumed() const override { return inner_->bytes_consumed(); }

 private:
  std::unique_ptr<EventReader> inner_;
  std::optional<std::int64_t> from_us_;
  std::optional<std::int64_t> to_us_;
  PolarityFilter polarity_;
  std::optional<std::int64_t> first_t_;
  bool done_ = false;
};

}  // namespace evlife::io::detail
