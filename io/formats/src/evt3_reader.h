// Prophesee RAW, EVT 3.0: `%` header, then little-endian 16-bit words
// decoded by Evt3Decoder (evt3_decoder.h, which documents the words).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "chunked_file.h"
#include "evt3_decoder.h"
#include "evlife/io/event_reader.h"
#include "prophesee_time_high.h"  // prophesee_skipped_kinds

namespace evlife::io {

class Evt3Reader final : public EventReader {
 public:
  /// Throws ReadError if the file cannot be opened or is not EVT 3.0.
  explicit Evt3Reader(const std::string& path);

  std::size_t read(std::span<Event> out) override;
  std::optional<SensorSize> sensor_size() const override { return sensor_; }
  std::string_view format_name() const override { return "evt3"; }
  const std::string& path() const override { return file_.path(); }
  std::uint64_t skipped_record_count() const override {
    return decoder_.trigger_count() + decoder_.other_count() + decoder_.before_time_base_count() +
           decoder_.before_address_count();
  }
  std::vector<SkippedKindCount> skipped_record_kinds() const override {
    return prophesee_skipped_kinds(decoder_.trigger_count(), decoder_.other_count(), decoder_.before_time_base_count(),
                                   decoder_.before_address_count());
  }
  std::uint64_t bytes_consumed() const override {
    return static_cast<std::uint64_t>(file_.offset());
  }
  std::uint64_t trigger_count() const override { return decoder_.trigger_count(); }

 private:
  static constexpr std::size_t kMaxEventsPerWord = Evt3Decoder::kMaxEventsPerWord;

  /// Decodes buffered words into `out` while a whole word's events still
  /// fit; returns the count; sets error_ on a fault.
  std::size_t decode(std::span<Event> out);

  ChunkedFile file_;
  std::optional<SensorSize> sensor_;
  Evt3Decoder decoder_;
  std::int64_t event_count_ = 0;
  // Events of one vector word that did not fit in a small caller buffer.
  std::array<Event, kMaxEventsPerWord> pending_{};
  std::size_t pending_begin_ = 0;
  std::size_t pending_end_ = 0;
  std::optional<ReadError> error_;
};

}  // namespace evlife::io
