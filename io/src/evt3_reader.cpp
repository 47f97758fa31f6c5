#include "evt3_reader.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <memory>

#include "prophesee_header.h"
#include "reader_registry.h"

namespace evlife::io {
namespace {

constexpr std::uint32_t kTimeHighRange = 1u << 12;
constexpr std::int64_t kTimeRangeUs = std::int64_t{1} << 24;
constexpr std::size_t kWordBytes = 2;

}  // namespace

Evt3Reader::Evt3Reader(const std::string& path) : file_(path) {
  const PropheseeHeader header = read_prophesee_header(file_);
  const std::string version = header.evt_version();
  if (version != "3.0") {
    throw ReadError(path, 0, -1,
                    "not a Prophesee EVT 3.0 RAW file (header says evt '" + version + "')");
  }
  sensor_ = header.sensor_size();
  if (sensor_) {
    width_ = static_cast<std::uint32_t>(std::min(sensor_->width, 2048));
    height_ = static_cast<std::uint32_t>(std::min(sensor_->height, 2048));
  }
}

std::size_t Evt3Reader::decode(std::span<Event> out) {
  std::size_t n = 0;
  const std::size_t words = file_.available() / kWordBytes;
  const std::uint8_t* bytes = file_.data();
  std::size_t i = 0;
  const auto fault = [&](const std::string& what) {
    error_.emplace(path(), file_.offset() + static_cast<std::int64_t>(i * kWordBytes),
                   event_count_ + static_cast<std::int64_t>(n), what);
  };
  // Each word may add up to kMaxEventsPerWord events: stop while that still fits.
  for (; i < words && n + kMaxEventsPerWord <= out.size(); ++i) {
    std::uint16_t w;
    std::memcpy(&w, bytes + i * kWordBytes, kWordBytes);
    switch (w >> 12) {
      case 0x0:  // ADDR_Y (bit 11: system type, ignored)
        y_ = w & 0x7FFu;
        if (y_ >= height_) {
          fault("EVT 3.0 row y=" + std::to_string(y_) + " outside the sensor");
          goto done;
        }
        break;
      case 0x2: {  // ADDR_X: one event
        const std::uint32_t x = w & 0x7FFu;
        if (x >= width_) {
          fault("EVT 3.0 event at x=" + std::to_string(x) + " outside the sensor");
          goto done;
        }
        out[n++] = Event{t_us_, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y_),
                         (w & 0x800u) != 0 ? std::int8_t{1} : std::int8_t{-1}};
        break;
      }
      case 0x3:  // VECT_BASE_X
        base_x_ = w & 0x7FFu;
        vector_p_ = (w & 0x800u) != 0 ? std::int8_t{1} : std::int8_t{-1};
        break;
      case 0x4:    // VECT_12
      case 0x5: {  // VECT_8
        const std::uint32_t span = (w >> 12) == 0x4 ? 12u : 8u;
        std::uint32_t mask = w & ((1u << span) - 1u);
        if (mask != 0 && base_x_ + static_cast<std::uint32_t>(std::bit_width(mask)) > width_) {
          fault("EVT 3.0 vector event beyond the sensor (base x=" + std::to_string(base_x_) + ")");
          goto done;
        }
        while (mask != 0) {
          const int bit = std::countr_zero(mask);
          mask &= mask - 1u;
          out[n++] = Event{t_us_, static_cast<std::uint16_t>(base_x_ + static_cast<std::uint32_t>(bit)),
                           static_cast<std::uint16_t>(y_), vector_p_};
        }
        base_x_ += span;
        break;
      }
      case 0x6:  // TIME_LOW
        t_us_ = (t_us_ & ~std::int64_t{0xFFF}) | (w & 0xFFF);
        break;
      case 0x8: {  // TIME_HIGH
        const std::uint32_t high = w & 0xFFFu;
        // A drop by more than half the range is a wrap of the 24-bit time.
        if (high < time_high_ && time_high_ - high > kTimeHighRange / 2) wrap_us_ += kTimeRangeUs;
        time_high_ = high;
        t_us_ = wrap_us_ + (static_cast<std::int64_t>(high) << 12);
        break;
      }
      case 0xA:  // EXT_TRIGGER
        ++trigger_count_;
        break;
      case 0x7:  // CONTINUED_4
      case 0xE:  // OTHERS
      case 0xF:  // CONTINUED_12
        ++other_count_;
        break;
      default:
        fault("unknown EVT 3.0 word type " + std::to_string(w >> 12));
        goto done;
    }
  }
done:
  file_.consume(i * kWordBytes);
  event_count_ += static_cast<std::int64_t>(n);
  return n;
}

std::size_t Evt3Reader::read(std::span<Event> out) {
  if (out.empty()) return 0;
  std::size_t n = 0;
  // Events left over from a vector word that did not fit last time.
  while (pending_begin_ < pending_end_ && n < out.size()) out[n++] = pending_[pending_begin_++];
  if (n == out.size() && n > 0) return n;
  if (error_) {
    if (n > 0) return n;
    throw *error_;
  }
  while (!error_) {
    if (file_.fill(kWordBytes) < kWordBytes) {
      if (file_.available() != 0) {
        error_.emplace(path(), file_.offset(), event_count_, "truncated EVT 3.0 word (1 trailing byte)");
      }
      break;
    }
    if (out.size() - n >= kMaxEventsPerWord) {
      n += decode(out.subspan(n));
    } else if (n == 0) {
      // Caller buffer smaller than one vector word: decode aside, hand out a part.
      pending_begin_ = 0;
      pending_end_ = decode(std::span<Event>(pending_.data(), pending_.size()));
      while (pending_begin_ < pending_end_ && n < out.size()) out[n++] = pending_[pending_begin_++];
      if (n > 0) break;
    } else {
      break;
    }
  }
  if (error_ && n == 0) throw *error_;
  return n;
}

namespace detail {
namespace {

SniffResult sniff_evt3(std::span<const std::byte> head, std::string_view /*path*/) {
  const auto header = parse_prophesee_header(head);
  return header && header->evt_version() == "3.0" ? SniffResult::by_content : SniffResult::no;
}

std::unique_ptr<EventReader> open_evt3(const std::string& path) {
  return std::make_unique<Evt3Reader>(path);
}

}  // namespace

const ReaderFormat evt3_format{"evt3", "Prophesee RAW EVT 3.0 (.raw, '% evt 3.0' header)",
                               &sniff_evt3, &open_evt3};

}  // namespace detail
}  // namespace evlife::io
