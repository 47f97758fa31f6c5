// MATLAB v5 .mat files of the reference code: variable `events`, an N×4
// numeric matrix with rows [x y p t] — t in µs, p ∈ {-1, 1} (0 also read as
// OFF), x y as stored. t in seconds where most of the first 1000 rows' float
// times are fractions (MATLAB users save seconds, which rounded to µs made
// every event's time 0 or 1), else in µs, rounded to the nearest. A fraction:
// further from a whole number than float noise (1e-12 of the value: µs
// computed as seconds x 1e6 stay µs); most, not any: one corrupt value among
// the first rows does not make a µs file seconds. The reference files hold 0-based coordinates (both
// axes span exactly 0..127, a DVS128's range; 1-based data would span
// 1..128), so nothing is added or subtracted. The format states no sensor
// size (sensor_size() = nullopt; the CLI then takes --sensor or the data's
// extent, which is 128×128 for the reference DVS128 recordings).
//
// Streaming: MATLAB stores matrices column-major, so row i needs one value
// from each of the 4 columns. Each column gets its own cursor over the same
// data element: a file offset for uncompressed data, an inflate stream for
// miCOMPRESSED data (cloned with inflateCopy once the previous column has
// been decompressed past, so opening costs one pass over columns 0-2).
// Memory is constant whatever N. Any storage type MATLAB uses (it may store
// a double matrix as int16 when the values fit) is decoded.
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "byte_cursor.h"
#include "input_file.h"
#include "reader_registry.h"

namespace evlife::io::detail {
namespace {

// MAT v5 data types (storage) and array classes.
enum : std::uint32_t {
  miINT8 = 1, miUINT8 = 2, miINT16 = 3, miUINT16 = 4, miINT32 = 5, miUINT32 = 6,
  miSINGLE = 7, miDOUBLE = 9, miINT64 = 12, miUINT64 = 13, miMATRIX = 14, miCOMPRESSED = 15,
};
enum : std::uint32_t { mxDOUBLE_CLASS = 6, mxUINT64_CLASS = 15 };

constexpr std::size_t kHeaderBytes = 128;
constexpr std::size_t kChunkEvents = 16384;

std::size_t storage_bytes(std::uint32_t type) {
  switch (type) {
    case miINT8: case miUINT8: return 1;
    case miINT16: case miUINT16: return 2;
    case miINT32: case miUINT32: case miSINGLE: return 4;
    case miDOUBLE: case miINT64: case miUINT64: return 8;
    default: return 0;
  }
}

std::uint32_t load_le32(const std::byte* p) {
  std::uint32_t v;
  std::memcpy(&v, p, 4);
  return v;  // little-endian host (x86/ARM); big-endian files are rejected
}

// What a matrix element says about itself.
struct MatrixHeader {
  std::string name;
  std::uint32_t array_class = 0;
  bool complex = false;
  std::vector<std::int64_t> dims;
  std::uint32_t data_type = 0;
  std::uint64_t data_bytes = 0;
  std::uint64_t data_offset = 0;  // from the start of the miMATRIX tag
  bool small = false;             // ≤ 4 data bytes kept inside the tag:
  std::vector<std::byte> small_data;
};

// Parses tag and subelements up to the real part's data; throws `fail(msg)`.
template <class Fail>
MatrixHeader parse_matrix_header(Cursor& c, Fail fail) {
  MatrixHeader h;
  std::uint64_t pos = 0;
  std::byte tag[8];
  auto read_exact = [&](std::span<std::byte> out) {
    if (c.read(out) != out.size()) fail("matrix header: " + c.error());
    pos += out.size();
  };
  // Reads a subelement tag; small format (size in the upper 16 bits of the
  // type word) keeps ≤4 bytes of data inside the tag.
  auto read_sub = [&](std::uint32_t& type, std::uint32_t& bytes, std::vector<std::byte>& data,
                      bool load) {
    read_exact(tag);
    type = load_le32(tag);
    if ((type >> 16) != 0) {
      bytes = type >> 16;
      type &= 0xFFFF;
      if (bytes > 4) fail("matrix header: bad small element");
      data.assign(tag + 4, tag + 4 + bytes);
      return true;  // small
    }
    bytes = load_le32(tag + 4);
    if (load) {
      if (bytes > (1u << 16)) fail("matrix header: implausible subelement size");
      data.resize((bytes + 7) / 8 * 8);
      read_exact(data);
      data.resize(bytes);
    }
    return false;
  };
  read_exact(tag);
  if (load_le32(tag) != miMATRIX) fail("expected a matrix element");
  std::uint32_t type = 0, bytes = 0;
  std::vector<std::byte> data;
  read_sub(type, bytes, data, true);  // array flags
  if (type != miUINT32 || bytes != 8) fail("matrix header: bad array flags");
  const std::uint32_t flags = load_le32(data.data());
  h.array_class = flags & 0xFF;
  h.complex = (flags & 0x0800) != 0;
  read_sub(type, bytes, data, true);  // dimensions
  if (type != miINT32 || bytes < 8 || bytes % 4 != 0) fail("matrix header: bad dimensions");
  for (std::size_t i = 0; i < bytes / 4; ++i)
    h.dims.push_back(static_cast<std::int32_t>(load_le32(data.data() + 4 * i)));
  read_sub(type, bytes, data, true);  // name
  if (type != miINT8) fail("matrix header: bad name");
  h.name.assign(reinterpret_cast<const char*>(data.data()), bytes);
  if (h.array_class < mxDOUBLE_CLASS || h.array_class > mxUINT64_CLASS) return h;  // not numeric
  h.small = read_sub(type, bytes, data, false);  // real part: data stays in the file
  if (h.small) h.small_data = data;
  h.data_type = type;
  h.data_bytes = bytes;
  h.data_offset = pos;
  return h;
}

enum class Convert { exact, round_us, seconds_to_us };

constexpr std::size_t kUnitSampleRows = 1000;  // the first rows, whose t tells seconds from µs
constexpr double kNoiseOfValue = 1e-12;  // float noise, relative: closer to a whole number is no fraction

bool is_float_storage(std::uint32_t type) { return type == miSINGLE || type == miDOUBLE; }

// Decodes `n` values of storage `type` into int64; for floating types checks
// they are integers (exact) or takes them as seconds, rounded to the nearest
// µs (seconds_to_us). Returns the number of values decoded before a
// non-integer / non-finite one.
std::size_t decode(std::uint32_t type, const std::byte* src, std::size_t n, std::int64_t* dst,
                   Convert convert) {
  auto ints = [&](auto tag) {
    using T = decltype(tag);
    for (std::size_t i = 0; i < n; ++i) {
      T v;
      std::memcpy(&v, src + i * sizeof(T), sizeof(T));
      dst[i] = static_cast<std::int64_t>(v);
    }
    return n;
  };
  auto floats = [&](auto tag) {
    using T = decltype(tag);
    for (std::size_t i = 0; i < n; ++i) {
      T v;
      std::memcpy(&v, src + i * sizeof(T), sizeof(T));
      const double d = convert == Convert::seconds_to_us ? static_cast<double>(v) * 1e6 : static_cast<double>(v);
      if (!(std::fabs(d) < 9.2e18)) return i;  // NaN, inf, out of int64
      const double r = convert == Convert::exact ? d : std::nearbyint(d);
      if (r != std::floor(r)) return i;
      dst[i] = static_cast<std::int64_t>(r);
    }
    return n;
  };
  switch (type) {
    case miINT8: return ints(std::int8_t{});
    case miUINT8: return ints(std::uint8_t{});
    case miINT16: return ints(std::int16_t{});
    case miUINT16: return ints(std::uint16_t{});
    case miINT32: return ints(std::int32_t{});
    case miUINT32: return ints(std::uint32_t{});
    case miINT64: return ints(std::int64_t{});
    case miUINT64: {
      const std::size_t k = ints(std::uint64_t{});
      for (std::size_t i = 0; i < k; ++i)
        if (dst[i] < 0) return i;  // above INT64_MAX
      return k;
    }
    case miSINGLE: return floats(float{});
    case miDOUBLE: return floats(double{});
    default: return 0;
  }
}

class MatReader final : public EventReader {
 public:
  explicit MatReader(const std::string& path) : file_(path) { open_events_variable(); }

  std::size_t read(std::span<Event> out) override {
    if (pending_) throw *pending_;
    if (next_index_ == rows_ && !end_checked_) {
      // Deflate data is verified by its checksum only at its end: a corrupt
      // stream can decode to plausible values, so report it at least here.
      end_checked_ = true;
      if (compressed_ && cursors_[3] && !cursors_[3]->finish())
        pending_.emplace(file_.path(), -1, static_cast<std::int64_t>(rows_),
                         "variable 'events' after the last row: " + cursors_[3]->error());
      if (!pending_ && trailing_fault_) pending_ = trailing_fault_;
      if (pending_) throw *pending_;
    }
    std::size_t n = 0;
    while (n < out.size() && next_index_ < rows_) {
      const std::size_t k = static_cast<std::size_t>(
          std::min<std::uint64_t>({out.size() - n, kChunkEvents, rows_ - next_index_}));
      // Values available in every column (fewer than k only on a fault).
      std::size_t good = k;
      std::string fault;
      for (int c = 0; c < 4; ++c) {
        const std::span<std::byte> raw = std::span(raw_[c]).first(k * value_bytes_);
        const std::size_t got = cursors_[c]->read(raw) / value_bytes_;
        if (got < good) {
          good = got;
          fault = cursors_[c]->error();
        }
        const std::size_t decoded = decode(data_type_, raw.data(), got, values_[c].data(),
                                           c != 3 ? Convert::exact
                                           : t_in_seconds_ ? Convert::seconds_to_us
                                                           : Convert::round_us);
        if (decoded < good) {
          good = decoded;
          fault = std::string(kColumnNames[c]) +
                  (c == 3 ? " is NaN, infinite or beyond +-9.2e18 us" : " is not a finite integer");
        }
      }
      const std::int64_t* xs = values_[0].data();
      const std::int64_t* ys = values_[1].data();
      const std::int64_t* ps = values_[2].data();
      const std::int64_t* ts = values_[3].data();
      std::size_t i = 0;
      for (; i < good; ++i) {
        const std::int64_t x = xs[i], y = ys[i], p = ps[i];
        if (static_cast<std::uint64_t>(x) > 65535 || static_cast<std::uint64_t>(y) > 65535) {
          fault = "coordinate out of range: x " + std::to_string(x) + ", y " + std::to_string(y);
          break;
        }
        if (p < -1 || p > 1) {
          fault = "polarity " + std::to_string(p) + " is not -1, 0 or 1";
          break;
        }
        out[n + i] = Event{ts[i], static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y),
                           p == 1 ? std::int8_t{1} : std::int8_t{-1}};
      }
      n += i;
      next_index_ += i;
      if (i < k) {
        pending_.emplace(file_.path(), byte_offset_of_event(static_cast<std::int64_t>(next_index_)),
                         static_cast<std::int64_t>(next_index_),
                         "variable 'events' row " + std::to_string(next_index_ + 1) + ": " + fault);
        break;
      }
    }
    if (n == 0 && pending_) throw *pending_;
    return n;
  }

  std::optional<SensorSize> sensor_size() const override { return std::nullopt; }
  std::string_view format_name() const override { return "mat"; }
  const std::string& path() const override { return file_.path(); }
  std::uint64_t bytes_consumed() const override {
    return rows_ == 0 ? file_.size_bytes()
                      : static_cast<std::uint64_t>(static_cast<double>(file_.size_bytes()) *
                                                   static_cast<double>(next_index_) /
                                                   static_cast<double>(rows_));
  }
  std::int64_t byte_offset_of_event(std::int64_t event_index) const override {
    if (compressed_) return -1;  // no meaningful offset inside deflate data
    return static_cast<std::int64_t>(data_file_offset_ +
                                     static_cast<std::uint64_t>(event_index) * value_bytes_);
  }

 private:
  static constexpr const char* kColumnNames[4] = {"x", "y", "p", "t"};

  /// Whether most float t values of the first kUnitSampleRows rows are
  /// fractions (read by a cursor of their own: the unit never depends on how
  /// the caller's reads cut the rows).
  bool most_first_times_are_fractions(const MatrixHeader& h) {
    if (!is_float_storage(data_type_) || rows_ == 0) return false;
    const std::uint64_t column_bytes = rows_ * value_bytes_;
    std::unique_ptr<Cursor> t;
    if (h.small) {
      const auto first = h.small_data.begin() + static_cast<std::ptrdiff_t>(3 * column_bytes);
      t = std::make_unique<MemoryCursor>(std::vector<std::byte>(first, first + static_cast<std::ptrdiff_t>(column_bytes)));
    } else if (!compressed_) {
      t = std::make_unique<RawCursor>(file_, data_file_offset_ + 3 * column_bytes, data_file_offset_ + 4 * column_bytes);
    } else {
      t = std::make_unique<InflateCursor>(*static_cast<const InflateCursor*>(cursors_[3].get()));
    }
    std::vector<std::byte> raw(static_cast<std::size_t>(std::min<std::uint64_t>(rows_, kUnitSampleRows)) * value_bytes_);
    const std::size_t n = t->read(raw) / value_bytes_;  // fewer at a fault: read() reports it
    std::size_t fractions = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double d = float_at(raw.data(), i);
      fractions += std::isfinite(d) && std::fabs(d - std::nearbyint(d)) > kNoiseOfValue * std::max(1.0, std::fabs(d));
    }
    return 2 * fractions > n;
  }

  double float_at(const std::byte* raw, std::size_t i) const {
    if (data_type_ == miSINGLE) {
      float v;
      std::memcpy(&v, raw + i * sizeof v, sizeof v);
      return static_cast<double>(v);
    }
    double v;
    std::memcpy(&v, raw + i * sizeof v, sizeof v);
    return v;
  }


  [[noreturn]] void fail(std::int64_t offset, const std::string& what) const {
    throw ReadError(file_.path(), offset, -1, what);
  }

  void open_events_variable() {
    std::byte header[kHeaderBytes];
    if (file_.read_at(0, header) != kHeaderBytes) fail(0, "truncated MAT-file header");
    if (std::memcmp(header, "MATLAB 5.0 MAT-file", 19) != 0) fail(0, "not a MATLAB v5 MAT-file");
    if (static_cast<char>(header[126]) != 'I' || static_cast<char>(header[127]) != 'M')
      fail(126, "big-endian MAT-files are not supported (save it on a little-endian machine)");
    std::vector<std::string> seen;
    std::uint64_t offset = kHeaderBytes;
    std::uint64_t element = offset;  // where the last element read began
    std::optional<std::pair<std::uint32_t, std::uint64_t>> unknown;  // the first element of another type, skipped
    while (offset + 8 <= file_.size_bytes()) {
      element = offset;
      std::byte tag[8];
      file_.read_at(offset, tag);
      const std::uint32_t type = load_le32(tag);
      const std::uint64_t bytes = load_le32(tag + 4);
      const std::uint64_t payload = offset + 8;
      auto header_fail = [&](const std::string& what) {
        fail(static_cast<std::int64_t>(offset), "variable header: " + what);
      };
      std::unique_ptr<Cursor> probe;
      if (type == miCOMPRESSED) {
        probe = std::make_unique<InflateCursor>(file_, payload, payload + bytes, InflateCursor::Wrapping::zlib,
                                                /*padding_bytes=*/7);  // an element padded to 8 bytes
      } else if (type == miMATRIX) {
        probe = std::make_unique<RawCursor>(file_, offset, payload + bytes);
      }
      if (!probe && !unknown) unknown = std::pair{type, offset};
      if (probe) {
        const MatrixHeader h = parse_matrix_header(*probe, header_fail);
        if (h.name == "events") {
          setup(h, type == miCOMPRESSED, offset, std::move(probe));
          t_in_seconds_ = most_first_times_are_fractions(h);
          find_trailing_fault(payload + bytes);
          return;
        }
        seen.push_back(h.name);
      }
      offset = payload + bytes;
    }
    std::string names;
    for (const std::string& s : seen) names += (names.empty() ? "" : ", ") + s;
    if (unknown)  // not a variable (a corrupt tag, or a type MATLAB does not write at the top)
      names += (names.empty() ? "no variable; " : "; ") + std::string("skipped an element of type ") +
               std::to_string(unknown->first) + " at byte offset " + std::to_string(unknown->second);
    const std::string found = "(found: " + (names.empty() ? "none" : names) + ")";
    // Elements end where the file does; a cut file ends inside one.
    if (offset < file_.size_bytes())
      fail(static_cast<std::int64_t>(offset), "truncated: a variable's 8-byte tag is cut after " +
                                                  std::to_string(file_.size_bytes() - offset) + " bytes; no variable 'events' before it " + found);
    if (offset > file_.size_bytes())
      fail(static_cast<std::int64_t>(element), "truncated or corrupt: the variable here states " +
                                                   std::to_string(offset - element - 8) + " bytes, past the file's end (" +
                                                   std::to_string(file_.size_bytes()) + " bytes); no variable 'events' before it " + found);
    fail(-1, "no variable 'events' in the MAT-file " + found);
  }

  // The elements after 'events' must end where the file does, as those before
  // it: bytes appended (garbage, a second file) or a later variable cut are
  // an input error after the last event (they were not looked at: exit 0).
  void find_trailing_fault(std::uint64_t offset) {
    const std::uint64_t size = file_.size_bytes();
    while (offset + 8 <= size) {
      std::byte tag[8];
      file_.read_at(offset, tag);
      const std::uint64_t end = offset + 8 + load_le32(tag + 4);
      if (end > size) {
        trailing_fault_.emplace(file_.path(), static_cast<std::int64_t>(offset), static_cast<std::int64_t>(rows_),
                                "after the variable 'events': an element stating " + std::to_string(end - offset - 8) +
                                    " bytes runs past the file's end (" + std::to_string(size) +
                                    " bytes): a later variable cut, or bytes appended to the file?");
        return;
      }
      offset = end;
    }
    if (offset < size) {
      trailing_fault_.emplace(file_.path(), static_cast<std::int64_t>(offset), static_cast<std::int64_t>(rows_),
                              "after the variable 'events': " + std::to_string(size - offset) +
                                  " bytes that are no whole element (bytes appended to the file?)");
    }
  }

  void setup(const MatrixHeader& h, bool compressed, std::uint64_t element_offset,
             std::unique_ptr<Cursor> probe) {
    auto bad = [&](const std::string& what) {
      fail(static_cast<std::int64_t>(element_offset), "variable 'events': " + what);
    };
    if (h.array_class < mxDOUBLE_CLASS || h.array_class > mxUINT64_CLASS || h.complex)
      bad("must be a real numeric matrix (class " + std::to_string(h.array_class) + ")");
    if (h.dims.size() != 2) bad("must be a 2-D N×4 matrix");
    value_bytes_ = storage_bytes(h.data_type);
    if (value_bytes_ == 0) bad("unsupported storage type " + std::to_string(h.data_type));
    data_type_ = h.data_type;
    const bool empty = h.dims[0] == 0 || h.dims[1] == 0;
    if (!empty && h.dims[1] != 4) {
      bad("must be N×4 with rows [x y p t], got " + std::to_string(h.dims[0]) + "×" +
          std::to_string(h.dims[1]) + (h.dims[0] == 4 ? " (transpose it)" : ""));
    }
    rows_ = empty ? 0 : static_cast<std::uint64_t>(h.dims[0]);
    if (h.data_bytes != rows_ * 4 * value_bytes_)
      bad("data size " + std::to_string(h.data_bytes) + " bytes does not match " +
          std::to_string(rows_) + "×4 values");
    compressed_ = compressed;
    for (int c = 0; c < 4; ++c) {
      raw_[c].resize(kChunkEvents * value_bytes_);
      values_[c].resize(kChunkEvents);
    }
    const std::uint64_t column_bytes = rows_ * value_bytes_;
    if (h.small) {  // e.g. one int8 row: the data sits in the element's tag
      compressed_ = true;  // no file offset to report
      for (std::uint64_t c = 0; c < 4; ++c) {
        const auto first = h.small_data.begin() + static_cast<std::ptrdiff_t>(c * column_bytes);
        cursors_[c] = std::make_unique<MemoryCursor>(
            std::vector<std::byte>(first, first + static_cast<std::ptrdiff_t>(column_bytes)));
      }
      return;
    }
    if (!compressed) {
      data_file_offset_ = element_offset + h.data_offset;
      for (int c = 0; c < 4; ++c)
        cursors_[c] = std::make_unique<RawCursor>(file_, data_file_offset_ + c * column_bytes,
                                                  data_file_offset_ + (c + 1) * column_bytes);
      return;
    }
    // The probe stopped right before the data; advance it column by column,
    // cloning a cursor at each column start.
    auto* z = static_cast<InflateCursor*>(probe.get());
    for (int c = 0; c < 4; ++c) {
      cursors_[c] = std::make_unique<InflateCursor>(*z);
      if (c < 3 && !z->skip(column_bytes)) {
        // Columns further on are unreachable: they report the fault when read.
        for (int d = c + 1; d < 4; ++d) cursors_[d] = std::make_unique<InflateCursor>(*z);
        break;
      }
    }
  }

  InputFile file_;
  std::uint64_t rows_ = 0;
  std::uint64_t next_index_ = 0;
  std::uint32_t data_type_ = 0;
  bool t_in_seconds_ = false;  // most float t of the first rows are fractions
  std::size_t value_bytes_ = 0;
  bool compressed_ = false;
  bool end_checked_ = false;
  std::uint64_t data_file_offset_ = 0;
  std::unique_ptr<Cursor> cursors_[4];
  std::vector<std::byte> raw_[4];
  std::vector<std::int64_t> values_[4];
  std::optional<ReadError> pending_;
  std::optional<ReadError> trailing_fault_;  // find_trailing_fault(): raised after the last event
};

SniffResult sniff_mat(std::span<const std::byte> head, std::string_view path) {
  constexpr std::string_view kText = "MATLAB 5.0 MAT-file";
  if (head.size() >= kHeaderBytes && std::memcmp(head.data(), kText.data(), kText.size()) == 0)
    return SniffResult::by_content;
  (void)path;  // v7.3 .mat files are HDF5: leave them to an HDF5 reader
  return SniffResult::no;
}

std::unique_ptr<EventReader> open_mat(const std::string& path) {
  return std::make_unique<MatReader>(path);
}

}  // namespace

const ReaderFormat mat_format{"mat",
                              "MATLAB v5 .mat with an N×4 matrix 'events', rows [x y p t] "
                              "(t in us, p -1/1), compressed or not",
                              &sniff_mat, &open_mat};

}  // namespace evlife::io::detail
