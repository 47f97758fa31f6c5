#include "prophesee_dat_reader.h"

#include <algorithm>
#include <cstring>
#include <memory>

#include "prophesee_header.h"
#include "reader_registry.h"

namespace evlife::io {
namespace {

constexpr std::uint8_t kTypeEvent2d = 0x00;
constexpr std::uint8_t kTypeEventCd = 0x0C;

}  // namespace

PropheseeDatReader::PropheseeDatReader(const std::string& path) : file_(path) {
  const PropheseeHeader header = read_prophesee_header(file_);
  if (header.fields.empty()) throw ReadError(path, 0, -1, "not a Prophesee DAT file (no '%' header)");
  if (file_.fill(2) < 2) {
    throw ReadError(path, file_.offset(), -1, "DAT file ends before its event type and size bytes");
  }
  const std::uint8_t type = file_.data()[0];
  const std::uint8_t size = file_.data()[1];
  if (type != kTypeEvent2d && type != kTypeEventCd) {
    throw ReadError(path, file_.offset(), -1,
                    "DAT event type " + std::to_string(type) + " is not CD events (0 or 12)");
  }
  if (size != kRecordBytes) {
    throw ReadError(path, file_.offset() + 1, -1,
                    "DAT record size " + std::to_string(size) + " (expected 8)");
  }
  file_.consume(2);
  data_offset_ = file_.offset();
  sensor_ = header.sensor_size();
  if (sensor_) {
    width_ = static_cast<std::uint32_t>(std::min(sensor_->width, 1 << 14));
    height_ = static_cast<std::uint32_t>(std::min(sensor_->height, 1 << 14));
  }
}

std::size_t PropheseeDatReader::read(std::span<Event> out) {
  if (error_) throw *error_;
  std::size_t n = 0;
  while (n < out.size()) {
    if (file_.fill(kRecordBytes) < kRecordBytes) {
      if (file_.available() != 0) {
        error_.emplace(path(), file_.offset(), event_count_,
                       "truncated DAT record (" + std::to_string(file_.available()) +
                           " trailing bytes)");
      }
      break;
    }
    const std::size_t records =
        std::min(file_.available() / static_cast<std::size_t>(kRecordBytes), out.size() - n);
    const std::uint8_t* bytes = file_.data();
    std::size_t i = 0;
    for (; i < records; ++i) {
      std::uint32_t t_raw;
      std::uint32_t w;
      std::memcpy(&t_raw, bytes + i * kRecordBytes, 4);
      std::memcpy(&w, bytes + i * kRecordBytes + 4, 4);
      const std::uint32_t x = w & 0x3FFF;
      const std::uint32_t y = (w >> 14) & 0x3FFF;
      const std::uint32_t p = w >> 28;
      if (x >= width_ || y >= height_ || p > 1) {
        error_.emplace(path(), file_.offset() + static_cast<std::int64_t>(i) * kRecordBytes,
                       event_count_,
                       "DAT record x=" + std::to_string(x) + " y=" + std::to_string(y) +
                           " p=" + std::to_string(p) + " is not a CD event on the sensor");
        break;
      }
      // 32-bit µs, wraps every 71.6 min
      out[n++] = Event{clock_.unwrap(t_raw), static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y),
                       p == 1 ? std::int8_t{1} : std::int8_t{-1}};
      ++event_count_;
    }
    file_.consume(i * static_cast<std::size_t>(kRecordBytes));
    if (error_) break;
  }
  if (error_ && n == 0) throw *error_;
  return n;
}

namespace detail {
namespace {

SniffResult sniff_prophesee_dat(std::span<const std::byte> head, std::string_view path) {
  const auto header = parse_prophesee_header(head);
  if (!header || !header->evt_version().empty()) return SniffResult::no;  // RAW, not DAT
  // After the header: event type byte (0 or 12) and record size 8.
  const auto end = static_cast<std::size_t>(header->size_bytes);
  if (end + 2 <= head.size()) {
    const auto type = static_cast<std::uint8_t>(head[end]);
    const auto size = static_cast<std::uint8_t>(head[end + 1]);
    if ((type == kTypeEvent2d || type == kTypeEventCd) && size == 8) return SniffResult::by_content;
  }
  return has_extension(path, ".dat") ? SniffResult::by_extension : SniffResult::no;
}

std::unique_ptr<EventReader> open_prophesee_dat(const std::string& path) {
  return std::make_unique<PropheseeDatReader>(path);
}

}  // namespace

const ReaderFormat prophesee_dat_format{
    "prophesee-dat", "Prophesee DAT CD events (.dat, '%' header, 8-byte records)",
    &sniff_prophesee_dat, &open_prophesee_dat};

}  // namespace detail
}  // namespace evlife::io
