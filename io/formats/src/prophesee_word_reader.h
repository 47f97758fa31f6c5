// Private: what the readers of Prophesee RAW EVT 2.0 and 2.1 share: the `%`
// header (its version checked, its sensor the coordinates' bounds), the
// TIME_HIGH clock, and the counts of the words skipped. Each format decodes
// its own words in read().
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "chunked_file.h"
#include "evlife/io/event_reader.h"
#include "prophesee_time_high.h"

namespace evlife::io {

class PropheseeWordReader : public EventReader {
 public:
  std::optional<SensorSize> sensor_size() const override { return sensor_; }
  std::string clock_wrap_note() const override { return PropheseeTimeHigh::wrap_note(); }
  const std::string& path() const override { return file_.path(); }
  std::uint64_t skipped_record_count() const override {
    return trigger_count_ + other_count_ + before_time_base_count_;
  }
  std::vector<SkippedKindCount> skipped_record_kinds() const override {
    return prophesee_skipped_kinds(trigger_count_, other_count_, before_time_base_count_);
  }
  std::uint64_t bytes_consumed() const override { return static_cast<std::uint64_t>(file_.offset()); }
  std::uint64_t trigger_count() const override { return trigger_count_; }

 protected:
  /// Opens `path` and reads its header; throws ReadError if the file cannot
  /// be opened or its header does not say `evt_version` ("2.0", "2.1").
  PropheseeWordReader(const std::string& path, std::string_view evt_version);

  ChunkedFile file_;
  std::optional<SensorSize> sensor_;
  std::uint32_t max_x_ = 0x7FF;  // inclusive bounds: the sensor, else the field width
  std::uint32_t max_y_ = 0x7FF;
  PropheseeTimeHigh time_high_;
  std::uint64_t trigger_count_ = 0;
  std::uint64_t other_count_ = 0;
  std::uint64_t before_time_base_count_ = 0;  // events before the first TIME_HIGH
  std::int64_t event_count_ = 0;
  std::optional<ReadError> error_;
};

}  // namespace evlife::io
