// Reads the augmented CSV back: exact header, then
// `x,y,t,p,lifetime,vx,vy,prediction_error` rows (empty prediction_error = NaN).
#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "augmented_formats.h"
#include "evlife/io/augmented_event_reader.h"
#include "line_reader.h"

namespace evlife::io::detail {
namespace {

// One byte changed, added or lost (a damaged byte, not another tool's name).
bool one_edit_apart(std::string_view a, std::string_view b) {
  if (a.size() < b.size()) std::swap(a, b);
  if (a.size() - b.size() > 1) return false;
  std::size_t i = 0;
  while (i < b.size() && a[i] == b[i]) ++i;
  const std::size_t skip_b = a.size() == b.size() ? 1 : 0;  // changed, else one byte of `a` is extra
  return a.substr(i + 1) == b.substr(std::min(b.size(), i + skip_b));
}

// evlife's header with one of its last four names damaged by a byte
// ("lifetimf"): eight fields, x,y,t,p first, three of the other four in
// place and the fourth one edit from its name. (x,y,t,p,lifetime,vx,vy,
// confidence is another tool's: read as plain events.)
bool damaged_header(std::string_view line) {
  std::string_view expected = kAugmentedCsvHeader;
  int fields = 0, matching_tail = 0;
  bool near = true;
  while (true) {
    const std::size_t got_end = line.find(','), want_end = expected.find(',');
    const std::string_view got = line.substr(0, got_end), want = expected.substr(0, want_end);
    if (fields < 4 && got != want) return false;
    if (fields >= 4 && got == want) ++matching_tail;
    if (fields >= 4 && got != want) near = near && one_edit_apart(got, want);
    ++fields;
    if (got_end == std::string_view::npos || want_end == std::string_view::npos) {
      return got_end == want_end && fields == 8 && matching_tail >= 3 && near;
    }
    line.remove_prefix(got_end + 1);
    expected.remove_prefix(want_end + 1);
  }
}

class AugmentedCsvReader final : public AugmentedEventReader {
 public:
  explicit AugmentedCsvReader(const std::string& path) : lines_(path) {
    std::string_view line;
    const bool has_line = next_line(line);
    if (pending_) throw *pending_;
    if (!has_line || strip_cr(line) != kAugmentedCsvHeader) {
      if (has_line && damaged_header(strip_cr(line)))  // never read as plain events, its lifetimes dropped
        throw AugmentedColumnsError(path, 0, -1,
                                    "evlife's augmented CSV with a damaged header: '" +
                                        std::string(strip_cr(line).substr(0, 100)) + "', not '" +
                                        std::string(kAugmentedCsvHeader) + "'");
      throw ReadError(path, 0, -1,
                      "not an augmented CSV: the first line must be '" +
                          std::string(kAugmentedCsvHeader) + "'");
    }
  }

  std::size_t read(std::span<AugmentedEvent> out) override {
    if (pending_) throw *pending_;
    std::size_t n = 0;
    std::string_view line;
    while (n < out.size()) {
      const std::uint64_t line_offset = lines_.offset();
      if (!next_line(line)) break;
      line = strip_cr(line);
      if (line.empty()) continue;
      AugmentedEvent a;
      const char* error = parse(line, a);
      if (error == nullptr && a.event.t_us < last_t_us_) error = "timestamp goes backwards";
      std::optional<std::string> values_fault;
      if (error == nullptr && (values_fault = augmented_values_fault(a))) error = values_fault->c_str();
      if (error != nullptr) {
        pending_.emplace(lines_.path(), static_cast<std::int64_t>(line_offset),
                         static_cast<std::int64_t>(index_),
                         "line " + std::to_string(line_number_) + ": " + error + ": '" +
                             std::string(line.substr(0, 100)) + "'");
        break;
      }
      last_t_us_ = a.event.t_us;
      out[n++] = a;
      ++index_;
    }
    if (n == 0 && pending_) throw *pending_;
    return n;
  }

  std::optional<SensorSize> sensor_size() const override { return std::nullopt; }
  std::string_view format_name() const override { return "augmented-csv"; }
  const std::string& path() const override { return lines_.path(); }

 private:
  static std::string_view strip_cr(std::string_view s) {
    return !s.empty() && s.back() == '\r' ? s.substr(0, s.size() - 1) : s;
  }

  template <class T>
  static bool field(const char*& p, const char* end, T& value, bool last) {
    const auto [ptr, ec] = std::from_chars(p, end, value);
    if (ec != std::errc() || ptr == p) return false;
    p = ptr;
    if (last) return p == end;
    if (p == end || *p != ',') return false;
    ++p;
    return true;
  }

  static const char* parse(std::string_view line, AugmentedEvent& a) {
    const char* p = line.data();
    const char* end = p + line.size();
    int polarity = 0;
    if (!field(p, end, a.event.x, false) || !field(p, end, a.event.y, false))
      return "bad x or y (integers 0-65535)";
    if (!field(p, end, a.event.t_us, false)) return "bad t (integer us)";
    if (!field(p, end, polarity, false) || (polarity != 1 && polarity != -1))
      return "bad p (1 or -1)";
    a.event.p = static_cast<std::int8_t>(polarity);
    if (!field(p, end, a.lifetime_us, false) || !field(p, end, a.vx_px_s, false) ||
        !field(p, end, a.vy_px_s, false))
      return "bad lifetime, vx or vy";
    if (p == end) {
      a.prediction_error_us = std::numeric_limits<float>::quiet_NaN();
    } else if (!field(p, end, a.prediction_error_us, true)) {
      return "bad prediction_error";
    }
    return nullptr;
  }

  // Next line without its '\n' (valid until the next call); false at end.
  bool next_line(std::string_view& line) {
    const LineReader::Next next = lines_.peek(line);
    if (next == LineReader::Next::too_long) {  // pending: the events read before it are kept
      pending_.emplace(lines_.path(), static_cast<std::int64_t>(lines_.offset()), static_cast<std::int64_t>(index_),
                       "line too long");
      return false;
    }
    if (next == LineReader::Next::end_of_file) return false;
    // The header alone without its '\n' loses no row: the empty file it is
    // (as with the '\n'; it was refused, then misread as no event file).
    const bool bare_header = line_number_ == 0 && strip_cr(line) == kAugmentedCsvHeader;
    if (lines_.peeked_unterminated() && !strip_cr(line).empty() && !bare_header) {
      // The writer ends every row: a last row without one was cut (a full
      // disk), and its last field may parse as another number.
      pending_.emplace(lines_.path(), static_cast<std::int64_t>(lines_.offset()), static_cast<std::int64_t>(index_),
                       "line " + std::to_string(line_number_ + 1) + ": truncated (the file ends inside it): '" +
                           std::string(line.substr(0, 100)) + "'");
      return false;
    }
    lines_.consume();
    ++line_number_;
    return true;
  }

  LineReader lines_;
  std::uint64_t line_number_ = 0, index_ = 0;
  std::int64_t last_t_us_ = INT64_MIN;
  std::optional<ReadError> pending_;
};

}  // namespace

std::unique_ptr<AugmentedEventReader> open_augmented_csv_reader(const std::string& path) {
  return std::make_unique<AugmentedCsvReader>(path);
}

}  // namespace evlife::io::detail
