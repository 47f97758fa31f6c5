#include "evt21_reader.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <memory>

#include "prophesee_header.h"  // is_prophesee_raw
#include "reader_registry.h"

namespace evlife::io {
namespace {

constexpr std::size_t kEvt21WordBytes = 8;
// Words after the header that decide the byte order: 512 words, 4 KiB.
constexpr std::size_t kLayoutProbeBytes = 512 * kEvt21WordBytes;

constexpr std::uint32_t kTypeNeg = 0, kTypePos = 1, kTypeTimeHigh = 8, kTypeTrigger = 10, kTypeOthers = 14;

std::uint32_t lower_half(std::uint64_t w) noexcept { return static_cast<std::uint32_t>(w); }
std::uint32_t x_of(std::uint64_t w) noexcept { return static_cast<std::uint32_t>((w >> 43) & 0x7FF); }
std::uint32_t y_of(std::uint64_t w) noexcept { return static_cast<std::uint32_t>((w >> 32) & 0x7FF); }

// The word at `bytes` (8 bytes) in `layout`.
std::uint64_t word_at(const std::uint8_t* bytes, Evt21Reader::Layout layout) noexcept {
  if (layout == Evt21Reader::Layout::whole_word) {
    std::uint64_t w;
    std::memcpy(&w, bytes, sizeof w);
    return w;
  }
  std::uint32_t upper, lower;
  std::memcpy(&upper, bytes, sizeof upper);
  std::memcpy(&lower, bytes + 4, sizeof lower);
  return (std::uint64_t{upper} << 32) | lower;
}

}  // namespace

Evt21Reader::Layout Evt21Reader::detect_layout(std::span<const std::uint8_t> words) noexcept {
  // Read in the wrong order, an event word's mask bits land in the type
  // field (11 of 16 values are reserved) and a TIME_HIGH word's zero half
  // lands where the type, x and y are: an OFF event at (0, 0) with a zero
  // time, which real streams rarely hold.
  const auto misfits = [&](Layout layout) {
    std::size_t n = 0;
    for (std::size_t k = 0; k + kEvt21WordBytes <= words.size(); k += kEvt21WordBytes) {
      const std::uint64_t w = word_at(words.data() + k, layout);
      const auto type = static_cast<std::uint32_t>(w >> 60);
      const bool known = type == kTypeNeg || type == kTypePos || type == kTypeTimeHigh || type == kTypeTrigger ||
                         type == kTypeOthers;
      n += !known || (type == kTypeTimeHigh && lower_half(w) != 0) ||
           (type <= kTypePos && (lower_half(w) == 0 || (w >> 32) == 0));
    }
    return n;
  };
  return misfits(Layout::upper_half_first) < misfits(Layout::whole_word) ? Layout::upper_half_first
                                                                          : Layout::whole_word;
}

Evt21Reader::Evt21Reader(const std::string& path) : PropheseeWordReader(path, "2.1") {
  const std::size_t probe = std::min(file_.fill(kLayoutProbeBytes), kLayoutProbeBytes);
  layout_ = detect_layout(std::span(file_.data(), probe / kEvt21WordBytes * kEvt21WordBytes));
}

std::size_t Evt21Reader::read(std::span<Event> out) {
  if (error_) throw *error_;
  std::size_t n = 0;
  // The events of the pending word, in x order, as far as `out` has room.
  const auto emit_pending = [&] {
    const std::int64_t t_us = time_high_.us() | static_cast<std::int64_t>((pending_word_ >> 54) & 0x3F);
    const std::int8_t p = (pending_word_ >> 60) == kTypePos ? std::int8_t{1} : std::int8_t{-1};
    while (pending_mask_ != 0 && n < out.size()) {
      const int bit = std::countr_zero(pending_mask_);
      pending_mask_ &= pending_mask_ - 1;
      out[n++] = Event{t_us, static_cast<std::uint16_t>(x_of(pending_word_) + static_cast<std::uint32_t>(bit)),
                       static_cast<std::uint16_t>(y_of(pending_word_)), p};
      ++event_count_;
    }
  };
  emit_pending();
  bool previous_word_zero = previous_word_zero_;
  while (n < out.size()) {
    if (file_.fill(kEvt21WordBytes) < kEvt21WordBytes) {
      if (file_.available() != 0) {
        error_.emplace(path(), file_.offset(), event_count_,
                       "truncated EVT 2.1 word (" + std::to_string(file_.available()) + " trailing bytes)");
      }
      break;
    }
    const std::size_t words = file_.available() / kEvt21WordBytes;
    const std::uint8_t* bytes = file_.data();
    std::size_t i = 0;
    for (; i < words && n < out.size(); ++i) {
      const std::uint64_t w = word_at(bytes + i * kEvt21WordBytes, layout_);
      const auto type = static_cast<std::uint32_t>(w >> 60);
      if (w == 0 && previous_word_zero) [[unlikely]] {  // a word of no pixel, twice: no encoder writes that
        error_.emplace(path(),
                       file_.offset() + static_cast<std::int64_t>(i * kEvt21WordBytes) -
                           static_cast<std::int64_t>(kEvt21WordBytes),
                       event_count_,
                       "zero-filled EVT 2.1 data (a block of the file never written: power lost while recording?)");
        break;
      }
      previous_word_zero = w == 0;
      if (type <= kTypePos) {
        const std::uint32_t mask = lower_half(w);
        const std::uint32_t x = x_of(w), y = y_of(w);
        if (mask == 0) {  // no pixel set: nothing to emit, counted
          ++other_count_;
          continue;
        }
        const std::uint32_t last_x = x + 31 - static_cast<std::uint32_t>(std::countl_zero(mask));
        if (last_x > max_x_ || y > max_y_) {
          error_.emplace(path(), file_.offset() + static_cast<std::int64_t>(i * kEvt21WordBytes), event_count_,
                         "EVT 2.1 event at x=" + std::to_string(last_x) + " y=" + std::to_string(y) +
                             " outside the sensor");
          break;
        }
        if (!time_high_.seen()) {  // no time yet: skipped, counted
          before_time_base_count_ += static_cast<std::uint64_t>(std::popcount(mask));
          continue;
        }
        pending_word_ = w;
        pending_mask_ = mask;
        emit_pending();  // what does not fit stays pending for the next call
      } else if (type == kTypeTimeHigh) {
        time_high_.update((w >> 32) & 0x0FFFFFFF);
      } else if (type == kTypeTrigger) {
        ++trigger_count_;
      } else if (type == kTypeOthers) {
        ++other_count_;
      } else {
        error_.emplace(path(), file_.offset() + static_cast<std::int64_t>(i * kEvt21WordBytes), event_count_,
                       "unknown EVT 2.1 word type " + std::to_string(type));
        break;
      }
    }
    file_.consume(i * kEvt21WordBytes);
    if (error_) break;
  }
  previous_word_zero_ = previous_word_zero;
  if (error_ && n == 0) throw *error_;
  return n;
}

namespace detail {
namespace {

SniffResult sniff_evt21(std::span<const std::byte> head, std::string_view /*path*/) {
  return is_prophesee_raw(head, "2.1") ? SniffResult::by_content : SniffResult::no;
}

std::unique_ptr<EventReader> open_evt21(const std::string& path) { return std::make_unique<Evt21Reader>(path); }

}  // namespace

const ReaderFormat evt21_format{"evt21",
                                "Prophesee RAW EVT 2.1 (.raw, '% evt 2.1' or '% format EVT21' header; GenX320, "
                                "64-bit words of 32 pixels)",
                                &sniff_evt21, &open_evt21};

}  // namespace detail
}  // namespace evlife::io
