#include "npy_events.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>

#include "column_layout.h"

namespace evlife::io::detail {
namespace {

constexpr std::size_t kSampleRows = 1000;  // rows looked at for the layout and the time unit
/// Bytes buffered per array (and at least one record).
constexpr std::size_t kBufferBytes = std::size_t{1} << 20;
/// A record is buffered whole: larger ones (a field of megabytes beside the
/// event's) are refused, not read into memory of their size.
constexpr std::size_t kMaxReadRecordBytes = std::size_t{64} << 20;
constexpr std::int64_t kNaT = INT64_MIN;  // datetime64's "not a time"

/// Why a type is not read, for messages.
std::string unread_type(const std::string& text) {
  return "of type " + text + ", which is not read (bool, int, uint, float32/64 and, for t, datetime64 in s, ms, us "
         "or ns are)";
}

/// One column of the event: in which array, where in its record, of which type.
struct Column {
  std::size_t array = 0;
  NpyScalar type;
  std::size_t offset = 0;
  std::string name;  ///< for messages: "field 'x'", "column 2", "array 'x.npy'"
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

Number load(const std::uint8_t* p, const NpyScalar& type) {
  const std::uint64_t bits = load_bits(p, type);
  Number n;
  switch (type.kind) {
    case 'f':
      n.is_float = true;
      n.f = type.bytes == 4 ? static_cast<double>(std::bit_cast<float>(static_cast<std::uint32_t>(bits)))
                            : std::bit_cast<double>(bits);
      break;
    case 'b':  // any byte but 0 is True, as NumPy reads it
      n.i = bits != 0 ? 1 : 0;
      break;
    case 'u':
      n.fits = bits <= static_cast<std::uint64_t>(INT64_MAX);
      n.i = static_cast<std::int64_t>(bits);
      break;
    default: {  // 'i', 'M': sign-extend
      const unsigned shift = 64 - 8 * static_cast<unsigned>(type.bytes);
      n.i = static_cast<std::int64_t>(bits << shift) >> shift;
    }
  }
  return n;
}

double as_double(const Number& n) { return n.is_float ? n.f : static_cast<double>(n.i); }

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
  if (n.is_float) return float_time_to_us(n.f, unit_ns, t_us);
  return n.fits && integer_time_to_us(n.i, unit_ns, t_us);
}

std::string number_text(const Number& n) {
  if (n.is_float) {
    std::array<char, 32> buf{};
    std::snprintf(buf.data(), buf.size(), "%.17g", n.f);
    return buf.data();
  }
  return n.fits ? std::to_string(n.i) : std::to_string(static_cast<std::uint64_t>(n.i));
}

/// An array's records, buffered: `records` of `record_bytes`, the first
/// `whole_records` of them on disk.
struct Records {
  NpyArray array;
  std::size_t record_bytes = 1;
  std::int64_t records = 0;
  std::int64_t whole_records = 0;
  std::vector<std::uint8_t> buffer;
  std::size_t pos = 0, end = 0;
  std::int64_t unread_bytes = 0;  ///< of available_bytes, not read from the cursor yet

  /// Makes at least `bytes` buffered unless the data ends first; returns what
  /// is. Asks the cursor for no more than the array holds, so that a short
  /// read is a fault (error() says which).
  std::size_t fill(std::size_t bytes) {
    if (end - pos >= bytes) return end - pos;
    std::memmove(buffer.data(), buffer.data() + pos, end - pos);
    end -= pos;
    pos = 0;
    const auto want = static_cast<std::size_t>(
        std::clamp<std::int64_t>(unread_bytes, 0, static_cast<std::int64_t>(buffer.size() - end)));
    const std::size_t got = array.bytes->read(std::as_writable_bytes(std::span(buffer)).subspan(end, want));
    end += got;
    unread_bytes -= static_cast<std::int64_t>(got);
    return end - pos;
  }
};

class NpyEventReader final : public EventReader {
 public:
  NpyEventReader(std::string path, std::string_view format, std::vector<NpyArray> arrays, NpyLayout layout,
                 const ReaderOptions& options, std::vector<ContainerStream> streams,
                 std::optional<ReadError> fault_after_events)
      : path_(std::move(path)), format_(format), streams_(std::move(streams)),
        fault_after_events_(std::move(fault_after_events)) {
    for (NpyArray& a : arrays) {
      Records r;
      r.array = std::move(a);
      records_.push_back(std::move(r));
    }
    if (layout == NpyLayout::column_arrays) {
      column_arrays();
    } else if (records_.front().array.header.fields.empty()) {
      plain_columns();
    } else {
      named_columns();
    }
    for (Records& r : records_) {
      if (r.record_bytes > kMaxReadRecordBytes)
        refuse(where(r) + "records of " + std::to_string(r.record_bytes) + " bytes (at most " +
               std::to_string(kMaxReadRecordBytes >> 20) + " MiB are read)");
      r.array.available_bytes = std::max<std::int64_t>(r.array.available_bytes, 0);
      r.whole_records = std::min(r.records, r.array.available_bytes / static_cast<std::int64_t>(r.record_bytes));
      r.buffer.resize(std::max(kBufferBytes / r.record_bytes, std::size_t{1}) * r.record_bytes);
      r.unread_bytes = r.array.available_bytes;
      whole_count_ = std::min(whole_count_, r.whole_records);
    }
    if (layout == NpyLayout::one_array && records_.front().array.header.fields.empty()) choose_plain_layout();
    if (layout == NpyLayout::one_array && !records_.front().array.name.empty())
      layout_ += ", array " + records_.front().array.name;  // which of an archive's arrays
    choose_time_unit(options);
  }

  std::size_t read(std::span<Event> out) override {
    if (pending_) throw *pending_;
    std::size_t n = 0;
    while (n < out.size() && next_ < whole_count_) {
      std::size_t batch = std::min(out.size() - n, static_cast<std::size_t>(whole_count_ - next_));
      for (Records& r : records_) {
        if (r.fill(r.record_bytes) < r.record_bytes) {
          batch = 0;  // the data ended early after all (a cut or corrupt compressed array)
          fault_in(r);
          break;
        }
        batch = std::min(batch, (r.end - r.pos) / r.record_bytes);
      }
      if (batch == 0) break;
      std::size_t i = 0;
      for (; i < batch; ++i) {
        if (!decode(i, out[n])) break;
        ++n;
        ++next_;
      }
      for (Records& r : records_) r.pos += i * r.record_bytes;
      if (pending_) break;
    }
    if (!pending_ && next_ == whole_count_) check_end();
    if (n == 0 && pending_) throw *pending_;
    return n;
  }

  std::optional<SensorSize> sensor_size() const override { return std::nullopt; }
  std::string_view format_name() const override { return format_; }
  std::string_view layout_name() const override { return layout_; }
  std::vector<ContainerStream> streams() const override { return streams_; }
  const std::string& path() const override { return path_; }
  std::int64_t byte_offset_of_event(std::int64_t event_index) const override {
    return records_.size() == 1 ? offset_in(0, event_index) : -1;
  }

 private:
  /// The file offset of record `index` of an array (-1 when compressed).
  std::int64_t offset_in(std::size_t array, std::int64_t index) const {
    const Records& r = records_[array];
    return r.array.file_offset < 0 ? -1 : r.array.file_offset + index * static_cast<std::int64_t>(r.record_bytes);
  }

  [[noreturn]] void refuse(const std::string& why) const {
    throw ReadError(path_, -1, -1, std::string(format_ == "npy" ? "not a readable .npy file: " : "not readable events: ") + why + "; " + npy_layouts());
  }

  /// "" for a lone .npy; "array 'x.npy': " in an archive.
  std::string where(const Records& r) const {
    return r.array.name.empty() ? std::string{} : "array '" + r.array.name + "': ";
  }

  void named_columns() {
    Records& r = records_.front();
    const NpyHeader& h = r.array.header;
    if (h.shape.size() != 1) refuse(where(r) + "a structured array of shape " + npy_shape_text(h));
    r.records = h.shape[0];
    r.record_bytes = h.record_bytes;
    layout_ = "structured";
    std::array<bool, 4> found{};
    std::string names;
    for (const NpyField& f : h.fields) {
      names += (names.empty() ? "" : ", ") + f.name;
      std::int64_t unit = 0;
      const int role = column_role(lower_ascii(f.name), unit);
      if (role < 0) continue;
      if (found[static_cast<std::size_t>(role)]) {  // which one holds it?
        refuse(where(r) + "its fields " + columns_[static_cast<std::size_t>(role)].name.substr(6) + " and '" + f.name +
               "' both name " + std::string(1, "xytp"[role]));
      }
      if (!f.scalar || (f.scalar->kind == 'M' && role != kT))
        refuse(where(r) + "its field '" + f.name + "' is " + unread_type(f.type_text));
      found[static_cast<std::size_t>(role)] = true;
      columns_[static_cast<std::size_t>(role)] = Column{0, *f.scalar, f.offset, "field '" + f.name + "'"};
      if (role == kT) name_unit_ns_ = unit;
    }
    if (std::find(found.begin(), found.end(), false) != found.end())
      refuse(where(r) + "its fields (" + names + ") do not name x, y, t and p");
  }

  void plain_columns() {
    Records& r = records_.front();
    const NpyHeader& h = r.array.header;
    if (h.shape.size() != 2 || h.shape[1] != 4) {
      const bool transposed = h.shape.size() == 2 && h.shape[0] == 4;
      refuse(where(r) + "an array of shape " + npy_shape_text(h) + (transposed ? " (transposed? save a.T)" : ""));
    }
    if (h.fortran_order) refuse(where(r) + "a Fortran-ordered (column-major) array; save np.ascontiguousarray(a)");
    if (!h.scalar || h.scalar->kind == 'M') refuse(where(r) + "an array " + unread_type(h.scalar_text));
    layout_ = "columns";
    r.records = h.shape[0];
    r.record_bytes = 4 * h.scalar->bytes;
    for (std::size_t c = 0; c < 4; ++c)
      columns_[c] = Column{0, *h.scalar, c * h.scalar->bytes, "column " + std::to_string(c)};
  }

  void column_arrays() {
    for (std::size_t role = 0; role < 4; ++role) {
      Records& r = records_[role];
      const NpyHeader& h = r.array.header;
      if (!h.scalar || (h.scalar->kind == 'M' && role != kT)) refuse(where(r) + unread_type(h.scalar_text));
      r.records = h.shape[0];
      r.record_bytes = h.scalar->bytes;
      if (r.records != records_.front().records)
        refuse("its arrays of x, y, t and p differ in length (" + records_.front().array.name + ": " +
               std::to_string(records_.front().records) + ", " + r.array.name + ": " + std::to_string(r.records) + ")");
      columns_[role] = Column{role, *h.scalar, 0, "value"};
      if (role == kT) {
        std::int64_t unit = 0;
        if (column_role(lower_ascii(npy_array_name(r.array.name)), unit) == kT) name_unit_ns_ = unit;
      }
    }
    layout_ = "arrays";
    for (const Records& r : records_) layout_ += (&r == &records_.front() ? " " : ", ") + r.array.name;
  }

  /// The first rows of every array (at most kSampleRows), for the layout and time unit.
  std::size_t sample_rows() {
    std::size_t rows = static_cast<std::size_t>(std::min<std::int64_t>(whole_count_, kSampleRows));
    for (Records& r : records_) rows = std::min(rows, r.fill(rows * r.record_bytes) / r.record_bytes);
    return rows;
  }
  Number sampled(std::size_t row, const Column& c) const {
    const Records& r = records_[c.array];
    return load(r.buffer.data() + r.pos + row * r.record_bytes + c.offset, c.type);
  }

  void choose_plain_layout() {
    const std::size_t rows = sample_rows();
    if (rows == 0) return;  // no whole row to tell the layout by: no event to read (a cut is said at the end)
    std::array<ColumnTraits, 4> traits{};
    for (std::size_t c = 0; c < 4; ++c) {
      ColumnTraits& tc = traits[c];
      for (std::size_t r = 0; r < rows; ++r) {
        const Number v = sampled(r, columns_[c]);
        std::int64_t unused = 0;
        tc.add(r, as_integer(v, -1, 1, unused), as_integer(v, 0, 65535, unused), v.is_float && v.f != std::floor(v.f),
               r > 0 && as_double(v) < as_double(sampled(r - 1, columns_[c])));
      }
      if (rows > 1)
        tc.moving = std::floor(as_double(sampled(0, columns_[c]))) != std::floor(as_double(sampled(rows - 1, columns_[c])));
    }
    const LayoutChoice choice = choose_layout(traits);
    if (choice.fitting == 0) {
      const auto record = [](std::size_t row) { return "record " + std::to_string(row); };
      const auto column_name = [](int c) { return "column " + std::to_string(c); };
      const auto value = [&](std::size_t row, int c) {
        return number_text(sampled(row, columns_[static_cast<std::size_t>(c)]));
      };
      refuse(where(records_.front()) + "no layout fits its first rows (" +
             no_layout_reasons(traits, record, column_name, value) + ")");
    }
    if (choice.fitting > 1)
      refuse(where(records_.front()) +
             "its first rows fit several layouts (save a structured array with named fields instead)");
    std::array<Column, 4> by_role{};
    for (std::size_t r = 0; r < 4; ++r) by_role[r] = columns_[static_cast<std::size_t>(choice.layout[r])];
    columns_ = by_role;
    layout_ = layout_text(choice.layout, 4);
  }

  void choose_time_unit(const ReaderOptions& options) {
    const Column& t = columns_[kT];
    if (!options.time_unit.empty()) {
      if (t.type.kind == 'M')  // its type states the unit: another one can only be wrong
        throw ReadError(path_, -1, -1, "--time-unit " + options.time_unit + ": the time column is datetime64, whose "
                                       "type states its unit");
      t_unit_ns_ = unit_ns(options.time_unit);
      if (t_unit_ns_ == 0)
        throw ReadError(path_, -1, -1, "unknown time unit '" + options.time_unit + "' (s, ms, us, ns)");
    } else if (name_unit_ns_ != 0) {
      t_unit_ns_ = name_unit_ns_;
    } else if (t.type.kind == 'M') {
      t_unit_ns_ = t.type.unit_ns;
    } else if (t.type.kind == 'f') {
      const std::size_t rows = sample_rows();
      bool fractional = false;
      for (std::size_t r = 0; r < rows && !fractional; ++r) {
        const Number v = sampled(r, t);
        fractional = v.f != std::floor(v.f);
      }
      t_unit_ns_ = fractional ? 1'000'000'000 : 1'000;
      unit_from_whole_times_ = !fractional;
    }
  }

  bool decode(std::size_t row, Event& e) {
    const Number x = sampled(row, columns_[kX]);
    const Number y = sampled(row, columns_[kY]);
    const Number t = sampled(row, columns_[kT]);
    const Number p = sampled(row, columns_[kP]);
    std::int64_t xv = 0, yv = 0, pv = 0, tv = 0;
    if (columns_[kT].type.kind == 'M' && t.i == kNaT) return fail(kT, t, "NaT, not a time");
    if (!as_integer(x, 0, 65535, xv)) return fail(kX, x, "not a coordinate (an integer 0..65535)");
    if (!as_integer(y, 0, 65535, yv)) return fail(kY, y, "not a coordinate (an integer 0..65535)");
    if (!as_integer(p, -1, 1, pv)) return fail(kP, p, "not a polarity (1 ON, 0 or -1 OFF)");
    // A fraction where the first rows' whole times made the unit µs: seconds
    // after all? (Rounded to µs it was read as another unit, silently.)
    if (unit_from_whole_times_ && t.is_float && t.f != std::floor(t.f))
      return fail(kT, t, "a fraction, but the whole times of the first rows made the unit µs (float times are in "
                         "seconds when they are fractions): say the unit with --time-unit s|ms|us|ns");
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
    const Column& c = columns_[static_cast<std::size_t>(role)];
    pending_.emplace(path_, offset_in(c.array, next_), next_,
                     where(records_[c.array]) + "record " + std::to_string(next_) + ": its " + c.name + " = " +
                         number_text(v) + " is " + why);
    return false;
  }

  /// An array's data ended before the records its size promised (a file cut
  /// while read, corrupt compressed data).
  void fault_in(const Records& r) {
    pending_.emplace(path_, byte_offset_of_event(next_), next_,
                     where(r) + "its data ends inside record " + std::to_string(next_) + " (" +
                         (r.array.bytes->error().empty() ? "cut short" : r.array.bytes->error()) + ")");
  }

  /// After the last whole record: the arrays must end where their shapes say
  /// (a cut one first: the one that ended the read).
  void check_end() {
    for (const Records& r : records_) {
      if (r.whole_records == whole_count_ && r.whole_records < r.records) {
        pending_.emplace(path_, offset_in(static_cast<std::size_t>(&r - records_.data()), r.whole_records),
                         r.whole_records,
                         where(r) + "the data ends inside record " + std::to_string(r.whole_records) + " of the " +
                             std::to_string(r.records) + " its header states (cut short?)");
        return;
      }
    }
    for (const Records& r : records_) {
      const std::int64_t extra = r.array.available_bytes - r.records * static_cast<std::int64_t>(r.record_bytes);
      if (extra > 0 && r.array.size_unknown) continue;  // a bound, not a size: the archive's cut is said below
      if (extra > 0) {
        // A stated size (a compressed archive member's) is checked by reading: are the bytes there?
        std::byte probe[1];
        const bool there = r.end > r.pos || r.array.bytes->read(probe) == 1;  // buffered, or still to read
        pending_.emplace(path_, offset_in(static_cast<std::size_t>(&r - records_.data()), r.records), r.records,
                         where(r) + (there ? std::to_string(extra) + " bytes follow the " + std::to_string(r.records) +
                                                 " records its header states"
                                           : "its stated size is " + std::to_string(extra) +
                                                 " bytes more than its data (" +
                                                 (r.array.bytes->error().empty() ? "a corrupt directory?"
                                                                                 : r.array.bytes->error()) +
                                                 ")"));
        return;
      }
      if (!r.array.bytes->finish()) {  // a compressed array: its stream's end and checksum
        pending_.emplace(path_, -1, r.records, where(r) + "after its last record: " + r.array.bytes->error());
        return;
      }
    }
    if (fault_after_events_)
      pending_.emplace(path_, fault_after_events_->byte_offset(), next_, fault_after_events_->reason());
  }

  std::string path_;
  std::string_view format_;
  std::vector<ContainerStream> streams_;
  std::optional<ReadError> fault_after_events_;
  std::vector<Records> records_;
  std::int64_t whole_count_ = INT64_MAX;    ///< whole records in every array
  std::int64_t next_ = 0;
  std::array<Column, 4> columns_{};  ///< by Role
  std::int64_t name_unit_ns_ = 0;
  std::int64_t t_unit_ns_ = 1000;
  bool unit_from_whole_times_ = false;  // µs, told from the first rows' whole float times alone
  std::string layout_;
  std::optional<ReadError> pending_;
};

}  // namespace

std::string npy_array_name(const std::string& member) {
  return member.ends_with(".npy") ? member.substr(0, member.size() - 4) : member;
}

std::string npy_layouts() {
  return std::string("readable: a structured array with fields ") + kColumnNames + " (others ignored), or an N x 4 " +
         "array laid out " + kUnnamedLayouts;
}

bool holds_events(const NpyHeader& h) {
  if (h.fields.empty()) return h.shape.size() == 2 && h.shape[1] == 4;
  std::array<bool, 4> found{};
  for (const NpyField& f : h.fields) {
    std::int64_t unit = 0;
    if (const int role = column_role(lower_ascii(f.name), unit); role >= 0) found[static_cast<std::size_t>(role)] = true;
  }
  return h.shape.size() == 1 && std::find(found.begin(), found.end(), false) == found.end();
}

bool holds_a_column(const NpyHeader& h) { return h.fields.empty() && h.shape.size() == 1; }

NpyHeader read_npy_header(Cursor& bytes, const std::string& path, const std::string& where) {
  std::vector<std::byte> head(12);
  const std::size_t got = bytes.read(head);
  head.resize(got);
  NpyHeaderResult parsed = parse_npy_header(head);
  if (parsed.needs_bytes > head.size() && parsed.needs_bytes <= kNpyMaxHeaderBytes + 12) {
    const std::size_t before = head.size();
    head.resize(parsed.needs_bytes);
    head.resize(before + bytes.read(std::span(head).subspan(before)));
    parsed = parse_npy_header(head);
  }
  if (!parsed.header) {
    throw ReadError(path, where.empty() ? parsed.offset : -1, -1,
                    (where.empty() ? "not a readable .npy file: " : where + ": not a readable .npy array: ") + parsed.why +
                        (parsed.needs_bytes != 0 && !bytes.error().empty() && !bytes.ended_short() ? " (" + bytes.error() + ")" : ""));
  }
  return *parsed.header;
}

std::unique_ptr<EventReader> make_npy_event_reader(std::string path, std::string_view format,
                                                   std::vector<NpyArray> arrays, NpyLayout layout,
                                                   const ReaderOptions& options, std::vector<ContainerStream> streams,
                                                   std::optional<ReadError> fault_after_events) {
  return std::make_unique<NpyEventReader>(std::move(path), format, std::move(arrays), layout, options,
                                          std::move(streams), std::move(fault_after_events));
}

}  // namespace evlife::io::detail
