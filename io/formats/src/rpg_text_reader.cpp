// RPG event-camera text format: one event per line `t x y p`, t in seconds
// (decimal), x y pixel coordinates (0-based, top-left), p 0 (OFF) or 1 (ON).
// Blank lines and lines starting with '#' are skipped. A first data line with
// exactly two integers `width height` (as written by rpg_e2vid tools) states
// the sensor size. Timestamps are parsed as decimals straight to integer µs
// (rounded half away from zero at the 7th decimal): no floating point, so no
// drift over long recordings. Numbers with exponents (NumPy's savetxt) read too.
#include <algorithm>
#include <cstring>
#include <vector>

#include "batch_line_offsets.h"
#include "decimal_number.h"
#include "line_reader.h"
#include "reader_registry.h"

namespace evlife::io::detail {
namespace {

bool is_space(char c) noexcept { return c == ' ' || c == '\t' || c == '\r'; }

void skip_spaces(const char*& p, const char* end) noexcept {
  while (p < end && is_space(*p)) ++p;
}

// Unsigned decimal integer ≤ max; false on no digits or overflow.
bool parse_uint(const char*& p, const char* end, std::uint64_t max, std::uint64_t& value) noexcept {
  const char* start = p;
  std::uint64_t v = 0;
  while (p < end && is_decimal_digit(*p)) {
    v = v * 10 + static_cast<std::uint64_t>(*p - '0');
    if (v > max) return false;
    ++p;
  }
  value = v;
  return p != start;
}

// [-+]digits[.digits] seconds → µs.
bool parse_seconds(const char*& p, const char* end, std::int64_t& t_us) noexcept {
  bool negative = false;
  if (p < end && (*p == '-' || *p == '+')) negative = *p++ == '-';
  std::uint64_t seconds = 0;
  const char* int_start = p;
  if (!parse_uint(p, end, 9'000'000'000'000ULL, seconds)) {
    if (p == int_start && p < end && *p == '.') {
      seconds = 0;  // ".5"
    } else {
      return false;
    }
  }
  std::uint64_t micro = 0;
  int digits = 0;
  bool round_up = false;
  if (p < end && *p == '.') {
    ++p;
    const char* frac_start = p;
    while (p < end && is_decimal_digit(*p)) {
      if (digits < 6) {
        micro = micro * 10 + static_cast<std::uint64_t>(*p - '0');
      } else if (digits == 6) {
        round_up = *p >= '5';
      }
      ++digits;
      ++p;
    }
    if (p == frac_start && p - 1 == int_start) return false;  // "." alone
  }
  for (int d = std::min(digits, 6); d < 6; ++d) micro *= 10;
  const auto magnitude = static_cast<std::int64_t>(seconds * 1'000'000 + micro + (round_up ? 1 : 0));
  t_us = negative ? -magnitude : magnitude;
  return true;
}

class RpgTextReader final : public EventReader {
 public:
  explicit RpgTextReader(const std::string& path) : lines_(path) {
    read_sensor_line();
  }

  std::size_t read(std::span<Event> out) override {
    if (pending_) throw *pending_;
    line_offsets_.begin(next_index_, out.size());
    std::size_t n = 0;
    while (n < out.size()) {
      std::string_view line;
      if (!next_line(line)) break;
      const std::uint64_t line_offset = lines_.offset();
      Event e;
      const LineKind kind = parse_line(line.data(), line.data() + line.size(), e);
      if (kind == LineKind::bad) {
        fail(line_offset, std::string(line.substr(0, 80)));
        break;
      }
      lines_.consume();
      ++line_number_;
      if (kind == LineKind::event) {
        line_offsets_.set(n, line_offset);
        out[n++] = e;
        ++next_index_;
      }
      comments_.count += kind == LineKind::comment && next_index_ > 0;
    }
    if (n == 0 && pending_) throw *pending_;
    return n;
  }

  std::optional<SensorSize> sensor_size() const override { return sensor_; }
  std::string_view format_name() const override { return "rpg-text"; }
  const std::string& path() const override { return lines_.path(); }
  std::uint64_t bytes_consumed() const override { return lines_.offset(); }
  std::int64_t byte_offset_of_event(std::int64_t event_index) const override {
    return line_offsets_.of(event_index, next_index_, pending_);
  }
  std::uint64_t skipped_record_count() const override { return comments_.count; }
  std::vector<SkippedKindCount> skipped_record_kinds() const override { return comments_.kinds(); }

 private:
  enum class LineKind { event, comment, skip, bad };

  LineKind parse_line(const char* p, const char* end, Event& e) const noexcept {
    skip_spaces(p, end);
    if (p == end) return LineKind::skip;
    if (*p == '#') return LineKind::comment;
    if (parse_plain_line(p, end, e)) return LineKind::event;
    return parse_exponent_line(p, end, e) ? LineKind::event : LineKind::bad;
  }

  // `t x y p` as the format writes it: t a plain decimal, x y p integers.
  static bool parse_plain_line(const char* p, const char* end, Event& e) noexcept {
    std::int64_t t_us = 0;
    std::uint64_t x = 0, y = 0, pol = 0;
    if (!parse_seconds(p, end, t_us)) return false;
    if (p == end || !is_space(*p)) return false;
    skip_spaces(p, end);
    if (!parse_uint(p, end, 65535, x) || p == end || !is_space(*p)) return false;
    skip_spaces(p, end);
    if (!parse_uint(p, end, 65535, y) || p == end || !is_space(*p)) return false;
    skip_spaces(p, end);
    bool minus = false;
    if (p < end && *p == '-') minus = (++p, true);  // tolerate -1 for OFF
    if (!parse_uint(p, end, 1, pol)) return false;
    skip_spaces(p, end);
    if (p != end) return false;
    if (minus && pol != 1) return false;
    e = Event{t_us, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y),
              (pol == 1 && !minus) ? std::int8_t{1} : std::int8_t{-1}};
    return true;
  }

  // The same four numbers with exponents or integral fractions, as NumPy's
  // savetxt writes them ("1.000000000000000000e+00"); only reached when the
  // plain parse refused the line.
  static bool parse_exponent_line(const char* p, const char* end, Event& e) noexcept {
    DecimalNumber field[4];
    for (DecimalNumber& number : field) {
      skip_spaces(p, end);
      const char* begin = p;
      while (p < end && !is_space(*p)) ++p;
      if (!parse_decimal(begin, p, number)) return false;
    }
    skip_spaces(p, end);
    std::int64_t t_us = 0;
    std::uint64_t x = 0, y = 0;
    const DecimalNumber& pol = field[3];
    if (p != end || !to_us(field[0], 1'000'000'000, t_us) || !as_uint(field[1], 65535, x) ||
        !as_uint(field[2], 65535, y) || !pol.integral || pol.int_part > 1 || (pol.negative && pol.int_part != 1))
      return false;
    e = Event{t_us, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y),
              (pol.int_part == 1 && !pol.negative) ? std::int8_t{1} : std::int8_t{-1}};
    return true;
  }

  // The next line, not consumed yet; false at end of file or when it is
  // longer than the buffer (then a pending error is set).
  bool next_line(std::string_view& line) {
    const LineReader::Next next = lines_.peek(line);
    if (next == LineReader::Next::too_long) fail(lines_.offset(), LineReader::too_long_note());
    return next == LineReader::Next::line;
  }

  void fail(std::uint64_t line_offset, const std::string& text) {
    pending_.emplace(lines_.path(), static_cast<std::int64_t>(line_offset),
                     static_cast<std::int64_t>(next_index_),
                     "line " + std::to_string(line_number_ + 1) +
                         ": expected 't x y p' (t seconds, x y integers, p 0 or 1), got '" + text +
                         "'");
  }

  // Optional "width height" first data line.
  void read_sensor_line() {
    while (true) {
      std::string_view line;
      if (!next_line(line)) return;
      const char* p = line.data();
      const char* nl = p + line.size();
      skip_spaces(p, nl);
      if (p == nl || *p == '#') {  // comment or blank: consume it
        lines_.consume();
        ++line_number_;
        continue;
      }
      std::uint64_t w = 0, h = 0;
      if (parse_uint(p, nl, 65536, w) && p < nl && is_space(*p)) {
        skip_spaces(p, nl);
        if (parse_uint(p, nl, 65536, h)) {
          skip_spaces(p, nl);
          if (p == nl && w > 0 && h > 0) {
            sensor_ = SensorSize{static_cast<int>(w), static_cast<int>(h)};
            lines_.consume();
            ++line_number_;
          }
        }
      }
      return;
    }
  }

  LineReader lines_;
  std::uint64_t line_number_ = 0;  // lines consumed
  std::uint64_t next_index_ = 0;
  CommentsAmongEvents comments_;
  BatchLineOffsets line_offsets_;
  std::optional<SensorSize> sensor_;
  std::optional<ReadError> pending_;
};

// Text with a first data line that parses as an event (or "width height").
SniffResult sniff_rpg_text(std::span<const std::byte> head, std::string_view path) {
  const bool txt = has_extension(path, ".txt");
  const std::string_view text = without_byte_order_mark({reinterpret_cast<const char*>(head.data()), head.size()});
  const char* p = text.data();
  const char* end = p + text.size();
  bool size_line_seen = false;
  while (p < end) {
    const char* nl = static_cast<const char*>(std::memchr(p, '\n', static_cast<std::size_t>(end - p)));
    if (nl == nullptr && !head_is_whole_file(head)) break;  // need a whole line (the file's last may lack '\n')
    if (nl == nullptr) nl = end;
    const char* q = p;
    skip_spaces(q, nl);
    if (q != nl && *q != '#') {
      std::int64_t t = 0;
      std::uint64_t a = 0, b = 0, c = 0;
      bool ok = parse_seconds(q, nl, t) && q < nl && is_space(*q);
      if (ok) skip_spaces(q, nl);
      ok = ok && parse_uint(q, nl, 65536, a);
      if (ok) skip_spaces(q, nl);
      if (ok && q == nl && !size_line_seen) {  // the optional first line "width height": events follow
        size_line_seen = true;
        p = nl == end ? end : nl + 1;
        continue;
      }
      ok = ok && parse_uint(q, nl, 65536, b);
      if (ok) skip_spaces(q, nl);
      if (ok && q == nl) return SniffResult::by_content;  // "t x y": RPG text lacking p (the reader names the line)
      ok = ok && parse_uint(q, nl, 1, c);
      if (ok) skip_spaces(q, nl);
      if (ok && q == nl) return SniffResult::by_content;
      break;
    }
    p = nl == end ? end : nl + 1;
  }
  return txt ? SniffResult::by_extension : SniffResult::no;
}

std::unique_ptr<EventReader> open_rpg_text(const std::string& path) {
  return std::make_unique<RpgTextReader>(path);
}

}  // namespace

const ReaderFormat rpg_text_format{"rpg-text",
                                   "RPG event-camera text, one event per line 't x y p' "
                                   "(t seconds, p 0/1; '#' comments)",
                                   &sniff_rpg_text, &open_rpg_text};

}  // namespace evlife::io::detail
