// Prophesee RAW, EVT 2.0: `%` header, then little-endian 32-bit words whose
// top 4 bits give the type: CD_OFF 0 / CD_ON 1 (t low 6 bits at 22-27,
// x at 11-21, y at 0-10), EV_TIME_HIGH 8 (bits 0-27 = t >> 6), EXT_TRIGGER 10
// (skipped, counted), OTHERS 14 / CONTINUED 15 (skipped, counted).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "chunked_file.h"
#include "prophesee_time_high.h"
#include "evlife/io/event_reader.h"

namespace evlife::io {

class Evt2Reader final : public EventReader {
 public:
  /// Throws ReadError if the file cannot be opened or is not EVT 2.0.
  explicit Evt2Reader(const std::string& path);

  std::size_t read(std::span<Event> out) override;
  std::optional<SensorSize> sensor_size() const override { return sensor_; }
  std::string_view format_name() const override { return "evt2"; }
  std::string clock_wrap_note() const override { return PropheseeTimeHigh::wrap_note(); }
  const std::string& path() const override { return file_.path(); }
  std::uint64_t skipped_record_count() const override {
    return trigger_count_ + other_count_ + before_time_base_count_;
  }
  std::vector<SkippedKindCount> skipped_record_kinds() const override {
    return prophesee_skipped_kinds(trigger_count_, other_count_, before_time_base_count_);
  }
  std::uint64_t bytes_consumed() const override {
    return static_cast<std::uint64_t>(file_.offset());
  }
  std::uint64_t trigger_count() const override { return trigger_count_; }

 private:
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
