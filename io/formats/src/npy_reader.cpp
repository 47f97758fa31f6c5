// NumPy .npy files (np.save), as Python users keep events:
//  - a structured array whose fields are named x, y, t|ts|time|timestamp
//    (optionally with a unit: t_us, timestamp_ns) and p|pol|polarity, of any
//    integer, bool, float or datetime64 type (other fields ignored), e.g.
//    what evlife.read returns, Tonic's and event_utils' arrays;
//  - an N x 4 array of one numeric type in a layout the CSV reader reads,
//    x,y,p,t, x,y,t,p or t,x,y,p, told from its first rows the same way
//    (column_layout.h).
// Time unit: ReaderOptions::time_unit (--time-unit), else the field name's,
// else datetime64's, else seconds where a float time column holds fractions
// among its first rows, else µs. Polarity 1 = ON, 0 or -1 = OFF.
#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <optional>
#include <string>

#include "chunked_file.h"
#include "column_layout.h"
#include "npy_header.h"
#include "reader_registry.h"

namespace evlife::io::detail {
namespace {

constexpr std::size_t kSampleRows = 1000;  // rows looked at for the layout and the time unit
/// Room for numpy's largest header (npy_header.cpp) and a buffer of records.
constexpr std::size_t kBufferBytes = std::size_t{2} << 20;

constexpr const char* kLayouts =
    "readable: a structured array with fields x, y, t|ts|time|timestamp and p|pol|polarity (others "
    "ignored), or an N x 4 array laid out x,y,p,t, x,y,t,p or t,x,y,p";

/// One column of the record: where and of which type.
struct Column {
  NpyScalar type;
  std::size_t offset = 0;
  std::string name;  ///< for messages: the field's name, or "column K"
};

std::uint64_t load_bits(const std::uint8_t* p, const NpyScalar& s) {
  std::uint64_t bits = 0;
  for (std::size_t i = 0; i < s.bytes; ++i) {
    const std::size_t shift = 8 * (s.big_endian ? s.bytes - 1 - i : i);
    bits |= static_cast<std::uint64_t>(p[i]) << shift;
  }
  return bits;
}

/// The value as a double for floats; as an exact integer otherwise.
struct Number {
  bool is_float = false;
  double f = 0;
  std::int64_t i = 0;
  bool fits = true;  // an unsigned 64-bit value beyond int64
};

Number load(const std::uint8_t* record, const Column& c) {
  const std::uint64_t bits = load_bits(record + c.offset, c.type);
  Number n;
  switch (c.type.kind) {
    case 'f':
      n.is_float = true;
      n.f = c.type.bytes == 4 ? static_cast<double>(std::bit_cast<float>(static_cast<std::uint32_t>(bits)))
                              : std::bit_cast<double>(bits);
      break;
    case 'u':
    case 'b':
      n.fits = bits <= static_cast<std::uint64_t>(INT64_MAX);
      n.i = static_cast<std::int64_t>(bits);
      break;
    default: {  // 'i', 'M': sign-extend
      const unsigned shift = 64 - 8 * static_cast<unsigned>(c.type.bytes);
      n.i = static_cast<std::int64_t>(bits << shift) >> shift;
    }
  }
  return n;
}

/// An integral value in [lo, hi].
bool as_integer(const Number& n, std::int64_t lo, std::int64_t hi, std::int64_t& v) {
  if (n.is_float) {
    if (!(n.f >= static_cast<double>(lo) && n.f <= static_cast<double>(hi)) || n.f != std::floor(n.f)) return false;
    v = static_cast<std::int64_t>(n.f);
    return true;
  }
  if (!n.fits || n.i < lo || n.i > hi) return false;
  v = n.i;
  return true;
}

/// The time in µs, rounded to nearest; false when it does not fit.
bool to_microseconds(const Number& n, std::int64_t unit_ns, std::int64_t& t_us) {
  if (n.is_float) {
    const double us = n.f * (static_cast<double>(unit_ns) / 1000.0);
    if (!std::isfinite(us) || std::fabs(us) >= 9.2e18) return false;
    t_us = std::llround(us);
    return true;
  }
  if (!n.fits) return false;
  if (unit_ns >= 1000) {
    const std::int64_t factor = unit_ns / 1000;
    if (n.i > INT64_MAX / factor || n.i < INT64_MIN / factor) return false;
    t_us = n.i * factor;
  } else {  // ns: to nearest µs, halves away from zero
    t_us = n.i / 1000 + (n.i % 1000 >= 500 ? 1 : 0) - (n.i % 1000 <= -500 ? 1 : 0);
  }
  return true;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string number_text(const Number& n) {
  if (n.is_float) {
    std::array<char, 32> buf{};
    std::snprintf(buf.data(), buf.size(), "%.17g", n.f);
    return buf.data();
  }
  return n.fits ? std::to_string(n.i) : std::to_string(static_cast<std::uint64_t>(n.i));
}

class NpyReader final : public EventReader {
 public:
  NpyReader(const std::string& path, const ReaderOptions& options) : file_(path, kBufferBytes) {
    NpyHeaderResult parsed = parse_npy_header(head(16));
    if (parsed.needs_bytes != 0 && parsed.needs_bytes <= kBufferBytes)
      parsed = parse_npy_header(head(parsed.needs_bytes));
    if (!parsed.header) throw ReadError(path, parsed.offset, -1, "not a readable .npy file: " + parsed.why);
    const NpyHeader& h = *parsed.header;
    data_offset_ = h.data_offset;
    record_bytes_ = h.record_bytes;
    if (h.fields.empty()) {
      plain_columns(h);
    } else {
      named_columns(h);
    }
    const std::int64_t data_bytes = file_.size_bytes() - data_offset_;
    const auto whole = static_cast<std::int64_t>(static_cast<std::uint64_t>(std::max<std::int64_t>(data_bytes, 0)) /
                                                 record_bytes_);
    records_on_disk_ = std::min(records_, whole);
    file_.seek(data_offset_);
    if (h.fields.empty()) choose_plain_layout();
    choose_time_unit(options);
  }

  std::size_t read(std::span<Event> out) override {
    if (pending_) throw *pending_;
    std::size_t n = 0;
    while (n < out.size() && next_ < records_on_disk_) {
      if (file_.fill(record_bytes_) < record_bytes_) break;  // the size was checked: an I/O race
      const std::size_t batch = std::min({file_.available() / record_bytes_, out.size() - n,
                                          static_cast<std::size_t>(records_on_disk_ - next_)});
      std::size_t i = 0;
      for (; i < batch; ++i) {
        if (!decode(file_.data() + i * record_bytes_, out[n])) break;
        ++n;
        ++next_;
      }
      file_.consume(i * record_bytes_);
      if (pending_) break;
    }
    if (!pending_ && next_ == records_on_disk_) check_size();
    if (n == 0 && pending_) throw *pending_;
    return n;
  }

  std::optional<SensorSize> sensor_size() const override { return std::nullopt; }
  std::string_view format_name() const override { return "npy"; }
  std::string_view layout_name() const override { return layout_; }
  const std::string& path() const override { return file_.path(); }
  std::uint64_t bytes_consumed() const override { return static_cast<std::uint64_t>(file_.offset()); }
  std::int64_t byte_offset_of_event(std::int64_t event_index) const override {
    return data_offset_ + event_index * static_cast<std::int64_t>(record_bytes_);
  }

 private:
  std::span<const std::byte> head(std::size_t bytes) {
    file_.fill(std::min(bytes, kBufferBytes));
    return {reinterpret_cast<const std::byte*>(file_.data()), file_.available()};
  }

  [[noreturn]] void refuse(const std::string& why) const {
    throw ReadError(path(), -1, -1, "not a readable .npy file: " + why + "; " + kLayouts);
  }

  void check_shape(const NpyHeader& h, std::size_t dims) {
    if (h.shape.size() != dims) {
      std::string shape;
      for (const std::int64_t d : h.shape) shape += (shape.empty() ? "" : ", ") + std::to_string(d);
      refuse("an array of shape (" + shape + ")");
    }
    records_ = h.shape[0];
    if (dims == 2 && h.fortran_order)
      refuse("a Fortran-ordered (column-major) array; save np.ascontiguousarray(a)");
  }

  void named_columns(const NpyHeader& h) {
    check_shape(h, 1);
    layout_ = "structured";
    std::array<bool, 4> found{};
    std::string names;
    for (const NpyField& f : h.fields) {
      names += (names.empty() ? "" : ", ") + f.name;
      std::int64_t unit = 0;
      const int role = column_role(lower(f.name), unit);
      if (role < 0 || found[static_cast<std::size_t>(role)]) continue;
      if (!f.scalar || (f.scalar->kind == 'M' && role != kT))
        refuse("its field '" + f.name + "' is of type " + f.type_text + ", not a number");
      found[static_cast<std::size_t>(role)] = true;
      columns_[static_cast<std::size_t>(role)] = Column{*f.scalar, f.offset, "field '" + f.name + "'"};
      if (role == kT) name_unit_ns_ = unit;
    }
    if (std::find(found.begin(), found.end(), false) != found.end())
      refuse("its fields (" + names + ") do not name x, y, t and p");
  }

  void plain_columns(const NpyHeader& h) {
    check_shape(h, 2);
    if (h.shape[1] != 4) refuse("an array of " + std::to_string(h.shape[1]) + " columns, not 4");
    if (!h.scalar || h.scalar->kind == 'M') refuse("an array of type " + h.scalar_text + ", not numbers");
    layout_ = "columns";
    record_bytes_ = 4 * h.scalar->bytes;
    for (std::size_t c = 0; c < 4; ++c)
      columns_[c] = Column{*h.scalar, c * h.scalar->bytes, "column " + std::to_string(c)};
  }

  /// The first rows (at most kSampleRows whole records), for the layout and time unit.
  std::span<const std::uint8_t> sample() {
    const std::size_t rows = static_cast<std::size_t>(std::min<std::int64_t>(records_on_disk_, kSampleRows));
    const std::size_t bytes = std::min(rows * record_bytes_, kBufferBytes) / record_bytes_ * record_bytes_;
    file_.fill(bytes);
    return {file_.data(), std::min(bytes, file_.available())};
  }

  void choose_plain_layout() {
    const std::span<const std::uint8_t> rows = sample();
    const std::size_t count = rows.size() / record_bytes_;
    std::array<ColumnTraits, 4> traits{};
    for (std::size_t c = 0; c < 4; ++c) {
      ColumnTraits& tc = traits[c];
      Number previous;
      for (std::size_t r = 0; r < count; ++r) {
        const Number v = load(rows.data() + r * record_bytes_, columns_[c]);
        std::int64_t unused = 0;
        tc.fractional = tc.fractional || (v.is_float && v.f != std::floor(v.f));
        tc.polarity = tc.polarity && as_integer(v, -1, 1, unused);
        tc.coordinate = tc.coordinate && as_integer(v, 0, 65535, unused);
        if (r > 0) tc.non_decreasing = tc.non_decreasing && !(as_double(v) < as_double(previous));
        previous = v;
      }
      if (count > 1) {
        const double first = as_double(load(rows.data(), columns_[c]));
        tc.moving = std::floor(first) != std::floor(as_double(previous));
      }
    }
    const LayoutChoice choice = choose_layout(traits);
    if (choice.fitting != 1) {
      refuse(choice.fitting == 0 ? "no layout fits its first rows"
                                 : "its first rows fit several layouts (save a structured array with named "
                                   "fields instead)");
    }
    std::array<Column, 4> by_role{};
    for (std::size_t r = 0; r < 4; ++r) by_role[r] = columns_[static_cast<std::size_t>(choice.layout[r])];
    columns_ = by_role;
    layout_ = layout_text(choice.layout, 4);
  }

  static double as_double(const Number& n) { return n.is_float ? n.f : static_cast<double>(n.i); }

  void choose_time_unit(const ReaderOptions& options) {
    const Column& t = columns_[kT];
    if (!options.time_unit.empty()) {
      t_unit_ns_ = unit_ns(options.time_unit);
      if (t_unit_ns_ == 0) throw ReadError(path(), -1, -1, "unknown time unit '" + options.time_unit + "' (s, ms, us, ns)");
    } else if (name_unit_ns_ != 0) {
      t_unit_ns_ = name_unit_ns_;
    } else if (t.type.kind == 'M') {
      t_unit_ns_ = t.type.unit_ns;
    } else if (t.type.kind == 'f') {
      const std::span<const std::uint8_t> rows = sample();
      bool fractional = false;
      for (std::size_t r = 0; r < rows.size() / record_bytes_ && !fractional; ++r) {
        const Number v = load(rows.data() + r * record_bytes_, t);
        fractional = v.f != std::floor(v.f);
      }
      t_unit_ns_ = fractional ? 1'000'000'000 : 1'000;
    }
  }

  bool decode(const std::uint8_t* record, Event& e) {
    const Number x = load(record, columns_[kX]);
    const Number y = load(record, columns_[kY]);
    const Number t = load(record, columns_[kT]);
    const Number p = load(record, columns_[kP]);
    std::int64_t xv = 0, yv = 0, pv = 0, tv = 0;
    if (!as_integer(x, 0, 65535, xv)) return fail(kX, x, "not a coordinate (an integer 0..65535)");
    if (!as_integer(y, 0, 65535, yv)) return fail(kY, y, "not a coordinate (an integer 0..65535)");
    if (!as_integer(p, -1, 1, pv)) return fail(kP, p, "not a polarity (1 ON, 0 or -1 OFF)");
    if (!to_microseconds(t, t_unit_ns_, tv))
      return fail(kT, t, "not a time in " + unit_name() + " that fits in 64-bit µs (--time-unit?)");
    e = Event{tv, static_cast<std::uint16_t>(xv), static_cast<std::uint16_t>(yv),
              pv == 1 ? std::int8_t{1} : std::int8_t{-1}};
    return true;
  }

  std::string unit_name() const {
    switch (t_unit_ns_) {
      case 1'000'000'000: return "s";
      case 1'000'000: return "ms";
      case 1: return "ns";
      default: return "µs";
    }
  }

  bool fail(Role role, const Number& v, const std::string& why) {
    pending_.emplace(path(), byte_offset_of_event(next_), next_,
                     "record " + std::to_string(next_) + ": its " + columns_[static_cast<std::size_t>(role)].name + " = " + number_text(v) +
                         " is " + why);
    return false;
  }

  /// After the last whole record: the file must end where the shape says.
  void check_size() {
    if (records_on_disk_ < records_) {
      pending_.emplace(path(), byte_offset_of_event(records_on_disk_), records_on_disk_,
                       "the file ends inside record " + std::to_string(records_on_disk_) + " of the " +
                           std::to_string(records_) + " its header states (cut short?)");
    } else if (const std::int64_t end = byte_offset_of_event(records_); file_.size_bytes() > end) {
      pending_.emplace(path(), end, records_,
                       std::to_string(file_.size_bytes() - end) + " bytes follow the " + std::to_string(records_) +
                           " records its header states");
    }
  }

  ChunkedFile file_;
  std::int64_t data_offset_ = 0;
  std::size_t record_bytes_ = 1;
  std::int64_t records_ = 0;          ///< as the header states
  std::int64_t records_on_disk_ = 0;  ///< whole records the file holds
  std::int64_t next_ = 0;
  std::array<Column, 4> columns_{};   ///< by Role
  std::int64_t name_unit_ns_ = 0;
  std::int64_t t_unit_ns_ = 1000;
  std::string layout_;
  std::optional<ReadError> pending_;
};

SniffResult sniff_npy(std::span<const std::byte> head, std::string_view path) {
  if (head.size() >= kNpyMagicBytes && std::memcmp(head.data(), kNpyMagic, kNpyMagicBytes) == 0)
    return SniffResult::by_content;
  return has_extension(path, ".npy") ? SniffResult::by_extension : SniffResult::no;
}

std::unique_ptr<EventReader> open_npy(const std::string& path, const ReaderOptions& options) {
  return std::make_unique<NpyReader>(path, options);
}

}  // namespace

const ReaderFormat npy_format{
    "npy",
    "NumPy .npy (np.save): fields x, y, t, p of a structured array, or N x 4 columns; t in µs or float s "
    "(else --time-unit)",
    &sniff_npy, nullptr, &open_npy, nullptr, "time-unit"};

}  // namespace evlife::io::detail
