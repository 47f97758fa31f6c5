// CSV / text events as other tools write them: one event per line, four
// columns in one of the layouts
//   x,y,p,t   (Prophesee metavision_file_to_csv)
//   x,y,t,p
//   t,x,y,p
// separated by commas, tabs or spaces; with or without a header line naming
// the columns (x, y, t|ts|time|timestamp, p|pol|polarity, optionally with a
// unit: t_us, timestamp(us), t [s]...; other named columns are ignored, so
// evlife's own augmented CSV reads too). Without a header the layout is told
// from the first lines (the polarity column holds only -1/0/1, the time
// column never decreases, x and y are integers) and must be unambiguous.
// Time unit: ReaderOptions::time_unit (--time-unit), else the header's, else
// seconds when the time column is written as a fraction (0.5, 1.5e-06), else
// µs (12, 1.2e+01). Numbers may have an exponent (NumPy's savetxt); times are
// parsed as decimals straight to integer µs (rounded to nearest), no floating
// point; x, y and p must be integral (12, 12.0, 1.2e+01).
// Polarity 1 = ON, 0 or -1 = OFF. '#' and '%' lines are comments.
#include <algorithm>
#include <array>
#include <cctype>
#include <cstring>
#include <vector>

#include "batch_line_offsets.h"
#include "column_layout.h"
#include "decimal_number.h"
#include "line_reader.h"
#include "reader_registry.h"

namespace evlife::io::detail {
namespace {

constexpr std::size_t kSampleLines = 1000;     // lines looked at to tell the layout

std::string layouts() {
  return std::string("accepted layouts: ") + kUnnamedLayouts +
         "; separated by commas, tabs or spaces; an optional header line naming the columns (" + kColumnNames +
         "; other columns ignored); t in seconds written as a fraction or integer µs (or say it with --time-unit "
         "s|ms|us|ns)";
}

struct Field {
  const char* begin;
  const char* end;
};

bool is_blank(char c) noexcept { return c == ' ' || c == '\t' || c == '\r'; }

/// Splits a line at `sep` (' ' = runs of blanks); at most `max` fields.
std::size_t split(const char* p, const char* end, char sep, Field* out, std::size_t max) {
  while (p < end && is_blank(*p)) ++p;
  while (end > p && is_blank(end[-1])) --end;
  std::size_t n = 0;
  while (p <= end && n < max + 1) {
    const char* q = p;
    if (sep == ' ') {
      while (q < end && !is_blank(*q)) ++q;
    } else {
      while (q < end && *q != sep) ++q;
    }
    const char* b = p;
    const char* e = q;
    while (b < e && is_blank(*b)) ++b;
    while (e > b && is_blank(e[-1])) --e;
    if (n < max) out[n] = Field{b, e};
    ++n;
    if (q >= end) break;
    p = q + 1;
    if (sep == ' ')
      while (p < end && is_blank(*p)) ++p;
  }
  return n;
}

bool parse_number(Field f, DecimalNumber& n) noexcept { return parse_decimal(f.begin, f.end, n); }

bool as_uint16(const DecimalNumber& n, std::uint16_t& v) noexcept {
  std::uint64_t value = 0;
  if (!as_uint(n, 65535, value)) return false;
  v = static_cast<std::uint16_t>(value);
  return true;
}

/// A header field's name, unquoted, in lower case.
std::string lower(Field f) {
  std::string s(f.begin, f.end);
  s.erase(std::remove(s.begin(), s.end(), '"'), s.end());
  return lower_ascii(std::move(s));
}

char separator_of(const char* p, const char* end) {
  if (std::memchr(p, ',', static_cast<std::size_t>(end - p)) != nullptr) return ',';
  if (std::memchr(p, '\t', static_cast<std::size_t>(end - p)) != nullptr) return '\t';
  if (std::memchr(p, ';', static_cast<std::size_t>(end - p)) != nullptr) return ';';
  return ' ';
}

bool is_blank_line(const char* p, const char* end) {
  while (p < end && is_blank(*p)) ++p;
  return p == end;
}

bool is_comment_or_blank(const char* p, const char* end) {
  while (p < end && is_blank(*p)) ++p;
  return p == end || *p == '#' || *p == '%';
}

/// What the head of a file says about its layout.
struct Detection {
  bool ok = false;
  bool header = false;       // first data line is a header
  char sep = ',';
  Layout layout{};
  int columns = 0;
  std::int64_t unit_ns = 0;  // 0 = not stated
  bool rpg_like = false;     // t,x,y,p with t in seconds: the rpg-text reader's
  bool no_layout_fits = false;  // the event lines were read, and no accepted layout fits them
  std::string why;           // when !ok
};

/// `whole_file`: [p, end) ends the file, so a last line without '\n' is whole
/// (a file's only line often lacks it); else that line may be cut and is not looked at.
Detection detect_lines(const char* p, const char* end, bool whole_file) {
  Detection d;
  std::vector<std::array<DecimalNumber, 4>> rows;
  std::vector<std::array<Field, 4>> row_fields;  // as written (views of the head), for the messages
  std::vector<std::size_t> row_lines;                  // 1-based line numbers
  std::size_t line_number = 0;
  bool first = true;
  while (p < end && rows.size() < kSampleLines) {
    const char* nl = static_cast<const char*>(std::memchr(p, '\n', static_cast<std::size_t>(end - p)));
    if (nl == nullptr && !whole_file) break;  // whole lines only
    if (nl == nullptr) nl = end;
    const char* line = p;
    p = nl == end ? end : nl + 1;
    ++line_number;
    if (is_comment_or_blank(line, nl)) continue;
    std::array<Field, 64> f{};
    if (first) {
      first = false;
      d.sep = separator_of(line, nl);
      const std::size_t n = split(line, nl, d.sep, f.data(), f.size());
      DecimalNumber probe;
      bool any_letter = false;
      for (std::size_t i = 0; i < std::min(n, f.size()); ++i)
        any_letter = any_letter || !parse_number(f[i], probe);
      if (any_letter) {
        d.header = true;
        d.layout = {-1, -1, -1, -1};
        for (std::size_t i = 0; i < std::min(n, f.size()); ++i) {
          std::int64_t unit = 0;
          const int role = column_role(lower(f[i]), unit);
          if (role < 0) continue;
          if (d.layout[role] >= 0) {  // which one holds it? (before: the first, silently)
            d.why = "the header line names " + std::string(1, "xytp"[role]) + " twice ('" +
                    lower(f[static_cast<std::size_t>(d.layout[role])]) + "' and '" + lower(f[i]) + "')";
            return d;
          }
          d.layout[role] = static_cast<int>(i);
          if (role == kT) d.unit_ns = unit;  // the unit of the time column read, not of another
        }
        d.columns = static_cast<int>(n);
        if (*std::min_element(d.layout.begin(), d.layout.end()) < 0) {
          d.why = "the header line does not name x, y, t and p columns";
          return d;
        }
        d.ok = true;
        return d;
      }
    }
    // A bad line ends the sample: the reader reports it after the events before it.
    const std::size_t n = split(line, nl, d.sep, f.data(), f.size());
    if (n != 4) {
      if (!rows.empty()) break;
      d.why = "a line has " + std::to_string(n) + " fields, not 4";
      return d;
    }
    std::array<DecimalNumber, 4> row;
    bool numbers = true;
    for (int i = 0; i < 4 && numbers; ++i)
      numbers = parse_number(f[static_cast<std::size_t>(i)], row[static_cast<std::size_t>(i)]);
    if (!numbers) {
      if (!rows.empty()) break;
      d.why = "a field is not a number";
      return d;
    }
    rows.push_back(row);
    row_fields.push_back({f[0], f[1], f[2], f[3]});
    row_lines.push_back(line_number);
  }
  if (rows.empty()) {
    d.why = "no event line found";
    return d;
  }
  std::array<ColumnTraits, 4> traits{};
  for (std::size_t c = 0; c < 4; ++c) {
    ColumnTraits& tc = traits[c];
    for (std::size_t r = 0; r < rows.size(); ++r) {
      const DecimalNumber& v = rows[r][c];
      // Compared as µs of seconds (what differs by less than 1 µs counts as equal); beyond
      // int64 µs (epoch ns read as seconds) as written: an overflow is no step back.
      bool below_previous = false;
      if (r > 0) {
        std::int64_t a = 0, b = 0;
        below_previous = to_us(rows[r - 1][c], 1'000'000'000, a) && to_us(v, 1'000'000'000, b)
                             ? b < a
                             : decimal_less(v, rows[r - 1][c]);
      }
      tc.add(r, v.integral && v.int_part <= 1, !v.negative && v.integral && v.int_part <= 65535,
             written_as_fraction(v), below_previous);
    }
    tc.moving = rows.size() > 1 && rows.front()[c].int_part != rows.back()[c].int_part;
  }
  const LayoutChoice choice = choose_layout(traits);
  if (choice.fitting == 0) {
    const auto line = [&](std::size_t row) { return "line " + std::to_string(row_lines[row]); };
    const auto field = [](int c) { return "field " + std::to_string(c + 1); };
    const auto value = [&](std::size_t row, int column) {
      const Field& written = row_fields[row][static_cast<std::size_t>(column)];
      return std::string(written.begin, written.end);
    };
    d.why = "no accepted layout fits the first lines (" + no_layout_reasons(traits, line, field, value) + ")";
    d.no_layout_fits = true;
    return d;
  }
  if (choice.fitting > 1) {
    d.why = "the first lines fit several layouts (add a header line, e.g. x,y,t,p)";
    return d;
  }
  d.ok = true;
  d.layout = choice.layout;
  d.columns = 4;
  d.rpg_like = d.layout == Layout{1, 2, 0, 3} && traits[0].fractional && d.sep == ' ';
  return d;
}

/// The layout of the head [p, end). A whole file's last line without '\n'
/// tells it too (in a small file it may be what tells t from x, y and p),
/// but it may be cut: where no layout fits with it (not where several do),
/// the lines before it decide, and the reader names the cut line after
/// their events (a cut file was refused with none of its events).
Detection detect(const char* p, const char* end, bool whole_file) {
  Detection d = detect_lines(p, end, whole_file);
  if (!d.no_layout_fits || !whole_file || p == end || end[-1] == '\n') return d;
  Detection before_last = detect_lines(p, end, false);
  return before_last.ok ? before_last : d;
}

class CsvTextReader final : public EventReader {
 public:
  CsvTextReader(const std::string& path, const ReaderOptions& options)
      : lines_(path) {
    const std::string_view head = lines_.buffered();
    const Detection d = detect(head.data(), head.data() + head.size(), lines_.buffered_to_end());
    if (!d.ok) throw ReadError(path, 0, -1, "not a readable CSV/text event file: " + d.why + "; " + layouts());
    sep_ = d.sep;
    layout_ = d.layout;
    columns_ = d.columns;
    skip_header_ = d.header;
    if (!options.time_unit.empty()) {
      unit_ns_ = unit_ns(options.time_unit);
      if (unit_ns_ == 0) throw ReadError(path, -1, -1, "unknown time unit '" + options.time_unit + "' (s, ms, us, ns)");
    } else if (d.unit_ns != 0) {
      unit_ns_ = d.unit_ns;
    } else {
      unit_ns_ = time_has_point(d) ? 1'000'000'000 : 1'000;
      unit_from_whole_times_ = unit_ns_ == 1'000;
    }
  }

  std::size_t read(std::span<Event> out) override {
    if (pending_) throw *pending_;
    line_offsets_.begin(next_index_, out.size());
    std::size_t n = 0;
    while (n < out.size()) {
      std::string_view line;
      if (!next_line(line)) break;
      const char* end = line.data() + line.size();
      ++line_number_;
      if (is_comment_or_blank(line.data(), end)) {
        comments_.count += next_index_ > 0 && !is_blank_line(line.data(), end);
      } else {
        if (skip_header_) {
          skip_header_ = false;
        } else if (const Parsed parsed = parse(line.data(), end, out[n]); parsed != Parsed::ok) {
          fail(lines_.offset(), std::string(line.substr(0, 80)), parsed);
          break;
        } else {
          line_offsets_.set(n, lines_.offset());
          ++n;
          ++next_index_;
        }
      }
      lines_.consume();
    }
    if (n == 0 && pending_) throw *pending_;
    return n;
  }

  std::optional<SensorSize> sensor_size() const override { return std::nullopt; }
  std::string_view format_name() const override { return "csv"; }
  const std::string& path() const override { return lines_.path(); }
  std::uint64_t bytes_consumed() const override { return lines_.offset(); }
  std::int64_t byte_offset_of_event(std::int64_t event_index) const override {
    return line_offsets_.of(event_index, next_index_, pending_);
  }
  std::uint64_t skipped_record_count() const override { return comments_.count; }
  std::vector<SkippedKindCount> skipped_record_kinds() const override { return comments_.kinds(); }

 private:
  bool time_has_point(const Detection& d) const {
    // Any time value written as a fraction among the sampled lines.
    const std::string_view head = lines_.buffered();
    const char* p = head.data();
    const char* end = p + head.size();
    bool header = d.header;
    std::size_t lines = 0;
    while (p < end && lines < kSampleLines) {
      const char* nl = static_cast<const char*>(std::memchr(p, '\n', static_cast<std::size_t>(end - p)));
      if (nl == nullptr) nl = end;
      if (!is_comment_or_blank(p, nl)) {
        if (header) {
          header = false;
        } else {
          std::array<Field, 64> f{};
          const std::size_t n = split(p, nl, d.sep, f.data(), f.size());
          const auto t = static_cast<std::size_t>(d.layout[kT]);
          DecimalNumber time;
          if (t < std::min(n, f.size()) && parse_number(f[t], time) && written_as_fraction(time)) return true;
          ++lines;
        }
      }
      p = nl + 1;
    }
    return false;
  }

  enum class Parsed { ok, bad, time_too_large, fraction_after_whole_times };

  Parsed parse(const char* p, const char* end, Event& e) const noexcept {
    std::array<Field, 64> f{};
    const std::size_t n = split(p, end, sep_, f.data(), f.size());
    if (n != static_cast<std::size_t>(columns_)) return Parsed::bad;
    DecimalNumber x, y, t, pol;
    if (!parse_number(f[static_cast<std::size_t>(layout_[kX])], x) ||
        !parse_number(f[static_cast<std::size_t>(layout_[kY])], y) ||
        !parse_number(f[static_cast<std::size_t>(layout_[kT])], t) ||
        !parse_number(f[static_cast<std::size_t>(layout_[kP])], pol))
      return Parsed::bad;
    e = Event{};  // a whole event (EventReader::read)
    if (!as_uint16(x, e.x) || !as_uint16(y, e.y)) return Parsed::bad;
    // A fraction where the first lines' whole times made the unit µs: seconds
    // after all? (Rounded to µs it was read as another unit, silently.)
    if (unit_from_whole_times_ && written_as_fraction(t)) return Parsed::fraction_after_whole_times;
    if (!to_us(t, unit_ns_, e.t_us)) return Parsed::time_too_large;
    if (!pol.integral || pol.int_part > 1) return Parsed::bad;
    e.p = (pol.int_part == 1 && !pol.negative) ? std::int8_t{1} : std::int8_t{-1};
    return Parsed::ok;
  }

  // The next line, not consumed yet; false at end of file or when it is
  // longer than the buffer (then a pending error is set).
  bool next_line(std::string_view& line) {
    const LineReader::Next next = lines_.peek(line);
    if (next == LineReader::Next::too_long) {
      ++line_number_;  // the too-long line is the one named
      fail(lines_.offset(), LineReader::too_long_note());
    }
    return next == LineReader::Next::line;
  }

  void fail(std::uint64_t line_offset, const std::string& text, Parsed why = Parsed::bad) {
    const std::string line = "line " + std::to_string(line_number_) + ": ";
    std::string what;
    if (why == Parsed::fraction_after_whole_times) {
      what = "'" + text + "': its t is a fraction, but the whole times of the first lines made the unit µs (a file "
             "without a unit is in seconds when its times are fractions): say the unit with --time-unit s|ms|us|ns";
    } else {
      what = "expected " + std::to_string(columns_) + " fields '" + layout_text(layout_, columns_) +
             "' (x y integers, p 0/1/-1, t a number), got '" + text + "'" +
             (why == Parsed::time_too_large ? "; its t is out of range for the time unit (epoch nanoseconds? "
                                              "--time-unit ns)"
                                            : "");
    }
    pending_.emplace(lines_.path(), static_cast<std::int64_t>(line_offset), static_cast<std::int64_t>(next_index_),
                     line + what);
  }

  LineReader lines_;
  std::uint64_t line_number_ = 0;
  std::uint64_t next_index_ = 0;
  CommentsAmongEvents comments_;
  char sep_ = ',';
  Layout layout_{};
  int columns_ = 4;
  bool skip_header_ = false;
  std::int64_t unit_ns_ = 1000;
  bool unit_from_whole_times_ = false;  // µs, told from the first lines' whole times alone
  std::optional<ReadError> pending_;
  BatchLineOffsets line_offsets_;
};

SniffResult sniff_csv_text(std::span<const std::byte> head, std::string_view path) {
  const bool csv = has_extension(path, ".csv") || has_extension(path, ".tsv");
  const std::string_view text = without_byte_order_mark({reinterpret_cast<const char*>(head.data()), head.size()});
  const Detection d = detect(text.data(), text.data() + text.size(), head_is_whole_file(head));
  // Space-separated `t x y p` with t in seconds stays the rpg-text reader's.
  if (d.ok && !d.rpg_like) return SniffResult::by_content;
  return csv ? SniffResult::by_extension : SniffResult::no;
}

std::unique_ptr<EventReader> open_csv_text(const std::string& path, const ReaderOptions& options) {
  return std::make_unique<CsvTextReader>(path, options);
}

}  // namespace

const ReaderFormat csv_text_format{
    "csv",
    "CSV/text events of other tools: x,y,p,t (metavision_file_to_csv), x,y,t,p or t,x,y,p; "
    "header line optional; comma, tab or space separated; t in s or µs (else --time-unit s|ms|us|ns)",
    &sniff_csv_text, nullptr, &open_csv_text, nullptr, "time-unit"};

}  // namespace evlife::io::detail
