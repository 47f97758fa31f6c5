#include "evt2_reader.h"

#include <algorithm>
#include <cstring>
#include <memory>

#include "prophesee_header.h"  // is_prophesee_raw
#include "reader_registry.h"

namespace evlife::io {
namespace {

constexpr std::size_t kEvt2WordBytes = 4;

}  // namespace

std::size_t Evt2Reader::read(std::span<Event> out) {
  if (error_) throw *error_;
  std::size_t n = 0;
  std::uint32_t previous_type = previous_type_;
  while (n < out.size()) {
    // Two words when the file has them: a zero word's check looks at the next.
    if (file_.fill(2 * kEvt2WordBytes) < kEvt2WordBytes) {
      if (file_.available() != 0) {
        error_.emplace(path(), file_.offset(), event_count_,
                       "truncated EVT 2.0 word (" + std::to_string(file_.available()) +
                           " trailing bytes)");
      }
      break;
    }
    // At most one event per word, so `words` never overruns `out`.
    const std::size_t buffered = file_.available() / kEvt2WordBytes;
    const std::size_t words = std::min(buffered, out.size() - n);
    const std::uint8_t* bytes = file_.data();
    std::size_t i = 0;
    for (; i < words; ++i) {
      std::uint32_t w;
      std::memcpy(&w, bytes + i * kEvt2WordBytes, kEvt2WordBytes);
      if (w == 0) [[unlikely]] {  // an OFF event at (0, 0), or the first of a zero-filled block
        if (i + 1 == buffered) {
          if (i > 0) break;  // the next word is not buffered yet: looked at after the refill
        } else if (std::uint32_t next; std::memcpy(&next, bytes + (i + 1) * kEvt2WordBytes, kEvt2WordBytes), next == 0) {
          error_.emplace(path(), file_.offset() + static_cast<std::int64_t>(i * kEvt2WordBytes), event_count_,
                         "zero-filled EVT 2.0 data: a pixel cannot fire twice in one microsecond (a block of the file "
                         "never written: power lost while recording?)");
          break;
        }
      }
      const std::uint32_t type = w >> 28;
      const bool continues_others = previous_type == 14 || previous_type == 15;
      previous_type = type;
      if (type <= 1) {  // CD_OFF / CD_ON
        const std::uint32_t x = (w >> 11) & 0x7FF;
        const std::uint32_t y = w & 0x7FF;
        if (x > max_x_ || y > max_y_) {
          error_.emplace(path(), file_.offset() + static_cast<std::int64_t>(i * kEvt2WordBytes),
                         event_count_,
                         "EVT 2.0 event at x=" + std::to_string(x) + " y=" + std::to_string(y) +
                             " outside the sensor");
          break;
        }
        if (!time_high_.seen()) {  // no time yet: skipped, counted
          ++before_time_base_count_;
          continue;
        }
        out[n++] = Event{time_high_.us() | static_cast<std::int64_t>((w >> 22) & 0x3F), static_cast<std::uint16_t>(x),
                         static_cast<std::uint16_t>(y), type == 1 ? std::int8_t{1} : std::int8_t{-1}};
        ++event_count_;
      } else if (type == 8) {  // EV_TIME_HIGH
        time_high_.update(w & 0x0FFFFFFF);
      } else if (type == 10) {  // EXT_TRIGGER
        ++trigger_count_;
      } else if (type == 14 || (type == 15 && continues_others)) {
        ++other_count_;  // OTHERS and the CONTINUED words that go on from it
      } else if (type == 15) {  // continues nothing: 0xFF bytes read so
        error_.emplace(path(), file_.offset() + static_cast<std::int64_t>(i * kEvt2WordBytes), event_count_,
                       "EVT 2.0 CONTINUED word with no OTHERS word before it: corrupt data "
                       "(a run of 0xFF bytes reads so)");
        break;
      } else {
        error_.emplace(path(), file_.offset() + static_cast<std::int64_t>(i * kEvt2WordBytes),
                       event_count_, "unknown EVT 2.0 word type " + std::to_string(type));
        break;
      }
    }
    file_.consume(i * kEvt2WordBytes);
    if (error_) break;
  }
  previous_type_ = previous_type;
  if (error_ && n == 0) throw *error_;
  return n;
}

namespace detail {
namespace {

SniffResult sniff_evt2(std::span<const std::byte> head, std::string_view /*path*/) {
  return is_prophesee_raw(head, "2.0") ? SniffResult::by_content : SniffResult::no;
}

std::unique_ptr<EventReader> open_evt2(const std::string& path) {
  return std::make_unique<Evt2Reader>(path);
}

}  // namespace

const ReaderFormat evt2_format{"evt2", "Prophesee RAW EVT 2.0 (.raw, '% evt 2.0' header)",
                               &sniff_evt2, &open_evt2};

}  // namespace detail
}  // namespace evlife::io
