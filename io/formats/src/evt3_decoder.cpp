#include "evt3_decoder.h"

#include <algorithm>
#include <bit>
#include <cstring>

namespace evlife::io {
namespace {

constexpr std::uint32_t kTimeHighRange = 1u << 12;
constexpr std::int64_t kTimeRangeUs = std::int64_t{1} << 24;

}  // namespace

void Evt3Decoder::set_geometry(std::uint32_t width, std::uint32_t height) noexcept {
  width_ = std::min(width, 2048u);
  height_ = std::min(height, 2048u);
}

Evt3Decoder::Result Evt3Decoder::decode(const std::uint8_t* bytes, std::size_t words,
                                        std::span<Event> out) {
  std::size_t n = 0;
  std::size_t i = 0;
  bool fault = false;
  bool fault_began_a_word_before = false;
  std::uint32_t previous_word = previous_word_;
  // Each word may add up to kMaxEventsPerWord events: stop while that still fits.
  for (; i < words && n + kMaxEventsPerWord <= out.size(); ++i) {
    std::uint16_t w;
    std::memcpy(&w, bytes + i * kWordBytes, kWordBytes);
    switch (w >> 12) {
      case 0x0:  // ADDR_Y (bit 11: system type, ignored)
        if (w == 0 && previous_word == 0) [[unlikely]] {  // row 0 set twice, nothing between: zero-filled data
          fault = true;
          fault_began_a_word_before = true;
          break;
        }
        if ((w & 0x7FFu) >= height_) {
          fault = true;  // y_ keeps its last good value
          break;
        }
        y_ = w & 0x7FFu;
        has_y_ = true;
        break;
      case 0x2: {  // ADDR_X: one event
        const std::uint32_t x = w & 0x7FFu;
        // (y_ is re-checked: the geometry may shrink between ROS messages.)
        if (x >= width_ || y_ >= height_) {
          fault = true;
          break;
        }
        if (!has_time_base_) {  // its time is not known yet: skipped, counted
          ++before_time_base_count_;
          break;
        }
        if (!has_y_) {  // nor its row (a stream cut between ADDR_Y and its events)
          ++before_address_count_;
          break;
        }
        out[n++] = Event{t_us_, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y_),
                         (w & 0x800u) != 0 ? std::int8_t{1} : std::int8_t{-1}};
        break;
      }
      case 0x3:  // VECT_BASE_X
        base_x_ = w & 0x7FFu;
        has_base_x_ = true;
        vector_p_ = (w & 0x800u) != 0 ? std::int8_t{1} : std::int8_t{-1};
        break;
      case 0x4:    // VECT_12
      case 0x5: {  // VECT_8
        const std::uint32_t span = (w >> 12) == 0x4 ? 12u : 8u;
        std::uint32_t mask = w & ((1u << span) - 1u);
        if (mask != 0 && (base_x_ + static_cast<std::uint32_t>(std::bit_width(mask)) > width_ ||
                          y_ >= height_)) {
          fault = true;
          break;
        }
        if (!has_time_base_) {
          before_time_base_count_ += static_cast<std::uint64_t>(std::popcount(mask));
          mask = 0;
        } else if (!has_y_ || !has_base_x_) {  // row or first column not known: skipped, counted
          before_address_count_ += static_cast<std::uint64_t>(std::popcount(mask));
          mask = 0;
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
        // Repeated every 16 us: the same value keeps TIME_LOW's bits. A drop
        // by half the range or more is a wrap of the 24-bit time (OpenEB's rule).
        if (has_time_base_ && high == time_high_) break;
        if (has_time_base_ && high < time_high_ && time_high_ - high >= kTimeHighRange / 2) wrap_us_ += kTimeRangeUs;
        time_high_ = high;
        has_time_base_ = true;
        t_us_ = wrap_us_ + (static_cast<std::int64_t>(high) << 12);
        break;
      }
      case 0xA:  // EXT_TRIGGER: edge = bit 0, id = bits 8-11
        ++trigger_count_;
        if (trigger_sink_ != nullptr) trigger_sink_->on_trigger(t_us_, w & 1, (w >> 8) & 0xF);
        break;
      case 0xE:  // OTHERS: may go on in CONTINUED words
        ++other_count_;
        break;
      case 0x7:    // CONTINUED_4
      case 0xF: {  // CONTINUED_12: only after OTHERS (a run of 0xFF bytes is not one)
        if (const std::uint32_t previous_type = previous_word >> 12;
            previous_type != 0xE && previous_type != 0x7 && previous_type != 0xF) {
          fault = true;
          break;
        }
        ++other_count_;
        break;
      }
      default:
        fault = true;
        break;
    }
    if (fault) {
      fault_word_ = w;
      break;
    }
    previous_word = w;
  }
  previous_word_ = previous_word;
  return Result{i, n, fault, fault_began_a_word_before};
}

std::string Evt3Decoder::fault_message() const {
  const unsigned type = fault_word_ >> 12u;
  switch (type) {
    case 0x0:
      if (fault_word_ == 0)
        return "zero-filled EVT 3.0 data: row y=0 set twice with nothing between, which no encoder writes (a "
               "block of the file never written: power lost while recording?)";
      return "EVT 3.0 row y=" + std::to_string(fault_word_ & 0x7FFu) + " outside the sensor";
    case 0x2:
      return "EVT 3.0 event at x=" + std::to_string(fault_word_ & 0x7FFu) + " y=" + std::to_string(y_) +
             " outside the sensor";
    case 0x4:
    case 0x5:
      return "EVT 3.0 vector event beyond the sensor (base x=" + std::to_string(base_x_) + ")";
    case 0x7:
    case 0xF:
      return "EVT 3.0 CONTINUED word (type " + std::to_string(type) +
             ") with no OTHERS word before it: corrupt data (a run of 0xFF bytes reads so)";
    default:
      return "unknown EVT 3.0 word type " + std::to_string(type);
  }
}

}  // namespace evlife::io
