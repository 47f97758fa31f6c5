// Prophesee DAT (CD events): `%` header, u8 event type (0 = Event2d,
// 12 = EventCD), u8 record size (8), then little-endian records
// u32 t (µs, unwrapped to 64 bits) + u32 w: x = w & 0x3FFF,
// y = (w >> 14) & 0x3FFF, p = w >> 28 (0 OFF, 1 ON).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "chunked_file.h"
#include "evlife/io/event_reader.h"
#include "wrapping_counter.h"

namespace evlife::io {

class PropheseeDatReader final : public EventReader {
 public:
  /// Throws ReadError if the file cannot be opened or is not a CD event DAT file.
  explicit PropheseeDatReader(const std::string& path);

  std::size_t read(std::span<Event> out) override;
  std::optional<SensorSize> sensor_size() const override { return sensor_; }
  std::string_view format_name() const override { return "prophesee-dat"; }
  std::string clock_wrap_note() const override { return decltype(clock_)::wrap_note(1); }
  const std::string& path() const override { return file_.path(); }
  std::uint64_t bytes_consumed() const override {
    return static_cast<std::uint64_t>(file_.offset());
  }
  std::int64_t byte_offset_of_event(std::int64_t event_index) const override {
    return data_offset_ + event_index * kRecordBytes;
  }

 private:
  static constexpr std::int64_t kRecordBytes = 8;

  ChunkedFile file_;
  std::optional<SensorSize> sensor_;
  std::uint32_t width_ = 1u << 14;  // x must be below (the sensor, else the field range)
  std::uint32_t height_ = 1u << 14;
  std::int64_t data_offset_ = 0;
  WrappingCounter<32> clock_;  // t
  std::int64_t event_count_ = 0;
  std::optional<ReadError> error_;
};

}  // namespace evlife::io
