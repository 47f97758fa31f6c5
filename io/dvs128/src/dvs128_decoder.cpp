#include "evlife/io/dvs128_decoder.h"

#include "evlife/io/dvs128_protocol.h"

namespace evlife::io {

bool Dvs128Decoder::decode_word(const std::uint8_t* w, Event& out) noexcept {
  ++counters_.words;
  const std::uint8_t ts_high = w[3];
  if ((ts_high & dvs128::kWrapFlag) != 0) {  // wrap is tested before reset (libcaer order)
    wrap_offset_us_ += dvs128::kWrapStep_us;
    ++counters_.wraps;
    return false;
  }
  if ((ts_high & dvs128::kResetFlag) != 0) {
    wrap_offset_us_ = 0;
    epoch_us_ = last_t_us_;
    ++counters_.resets;
    return false;
  }
  const auto address = static_cast<std::uint16_t>(w[0] | (w[1] << 8));
  if ((address & dvs128::kSyncFlag) != 0) {
    ++counters_.sync_events;
    return false;
  }
  const auto ts_us = static_cast<std::uint16_t>((w[2] | (ts_high << 8)) & dvs128::kTimestampMask);
  std::int64_t t_us = epoch_us_ + wrap_offset_us_ + ts_us;
  if (t_us < last_t_us_) {  // corrupt or reordered word: keep the stream monotonic, count it
    ++counters_.time_regressions;
    t_us = last_t_us_;
  }
  last_t_us_ = t_us;
  const int raw_x = (address >> 1) & 0x7F;
  const int raw_y = (address >> 8) & 0x7F;
  out = Event{t_us, static_cast<std::uint16_t>(dvs128::kWidth - 1 - raw_x),
               static_cast<std::uint16_t>(dvs128::kHeight - 1 - raw_y),
               (address & 0x01) == 0 ? std::int8_t{1} : std::int8_t{-1}};
  ++counters_.pixel_events;
  return true;
}

Dvs128Decoder::Result Dvs128Decoder::decode(std::span<const std::uint8_t> bytes,
                                            std::span<Event> out) noexcept {
  Result r;
  std::size_t n = 0;  // events written
  std::size_t i = 0;  // bytes consumed
  // Complete a word split across two transfers first.
  if (partial_size_ > 0) {
    if (out.empty()) return r;
    while (partial_size_ < 4 && i < bytes.size()) partial_[partial_size_++] = bytes[i++];
    if (partial_size_ < 4) {
      r.bytes_consumed = i;
      return r;
    }
    partial_size_ = 0;
    if (decode_word(partial_, out[n])) ++n;
  }
  const std::size_t whole_end = i + (bytes.size() - i) / 4 * 4;
  while (i < whole_end && n < out.size()) {
    if (decode_word(bytes.data() + i, out[n])) ++n;
    i += 4;
  }
  // Keep a trailing partial word only when everything before it was decoded.
  if (i == whole_end) {
    while (i < bytes.size()) partial_[partial_size_++] = bytes[i++];
  }
  r.bytes_consumed = i;
  r.events_written = n;
  return r;
}

}  // namespace evlife::io
