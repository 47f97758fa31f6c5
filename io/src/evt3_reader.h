// Prophesee RAW, EVT 3.0: `%` header, then little-endian 16-bit words, type
// in the top 4 bits. State words set the row (ADDR_Y 0), the time (TIME_LOW 6:
// bits 0-11, TIME_HIGH 8: bits 12-23, a 24-bit counter unwrapped to 64 bits)
// and a vector base (VECT_BASE_X 3: x + polarity); events come from ADDR_X 2
// (one event) and VECT_12 4 / VECT_8 5 (a bit mask of up to 12 / 8 events
// at base x + i, base x then advances by 12 / 8). EXT_TRIGGER 10 is skipped
// and counted, CONTINUED_4 7, OTHERS 14, CONTINUED_12 15 are skipped.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "chunked_file.h"
#include "evlife/io/event_reader.h"

namespace evlife::io {

class Evt3Reader final : public EventReader {
 public:
  /// Throws ReadError if the file cannot be opened or is not EVT 3.0.
  explicit Evt3Reader(const std::string& path);

  std::size_t read(std::span<Event> out) override;
  std::optional<SensorSize> sensor_size() const override { return sensor_; }
  std::string_view format_name() const override { return "evt3"; }
  const std::string& path() const override { return file_.path(); }
  std::uint64_t skipped_record_count() const override { return trigger_count_ + other_count_; }
  std::uint64_t bytes_consumed() const override {
    return static_cast<std::uint64_t>(file_.offset());
  }
  std::uint64_t trigger_count() const noexcept { return trigger_count_; }

 private:
  static constexpr std::size_t kMaxEventsPerWord = 12;

  /// Decodes buffered words into `out` while a whole word's events still
  /// fit; returns the count; sets error_ on a fault.
  std::size_t decode(std::span<Event> out);

  ChunkedFile file_;
  std::optional<SensorSize> sensor_;
  std::uint32_t width_ = 2048;  // x must be below (the sensor, else the field range)
  std::uint32_t height_ = 2048;
  // Decoder state.
  std::uint32_t y_ = 0;
  std::uint32_t base_x_ = 0;
  std::int8_t vector_p_ = 1;
  std::uint32_t time_high_ = 0;  // last 12-bit TIME_HIGH
  std::int64_t wrap_us_ = 0;     // added per 24-bit wrap
  std::int64_t t_us_ = 0;
  std::uint64_t trigger_count_ = 0;
  std::uint64_t other_count_ = 0;
  std::int64_t event_count_ = 0;
  // Events of one vector word that did not fit in a small caller buffer.
  std::array<Event, kMaxEventsPerWord> pending_{};
  std::size_t pending_begin_ = 0;
  std::size_t pending_end_ = 0;
  std::optional<ReadError> error_;
};

}  // namespace evlife::io
