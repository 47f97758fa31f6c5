// Private: the header of a NumPy .npy file (numpy.lib.format, versions 1-3):
// "\x93NUMPY", major, minor, a little-endian u16 (v1) or u32 (v2, v3) header
// length, then a Python dict literal {'descr': ..., 'fortran_order': ...,
// 'shape': (...)} padded with spaces to a newline. Parsed without Python: a
// literal subset (strings, integers, True/False/None, tuples, lists, dicts),
// bounded in depth and size.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace evlife::io::detail {

inline constexpr char kNpyMagic[] = "\x93NUMPY";
inline constexpr std::size_t kNpyMagicBytes = 6;
/// numpy writes headers of a few hundred bytes; a file with thousands of
/// fields stays well below this.
inline constexpr std::size_t kNpyMaxHeaderBytes = std::size_t{1} << 20;

/// One scalar type of a .npy dtype ('<i8', '|u1', '>f4', '|b1', '<M8[us]').
struct NpyScalar {
  char kind = 0;              ///< 'b' bool, 'i' int, 'u' unsigned, 'f' float, 'M' datetime64
  std::size_t bytes = 0;      ///< 1, 2, 4 or 8
  bool big_endian = false;
  std::int64_t unit_ns = 0;   ///< datetime64's unit ([s], [ms], [us], [ns]); 0 otherwise
};

/// A field of a structured dtype that evlife may read.
struct NpyField {
  std::string name;           ///< as written (numpy's titles dropped)
  std::size_t offset = 0;     ///< bytes from the record's start
  std::optional<NpyScalar> scalar;  ///< empty: a type evlife does not read (strings, subarrays...)
  std::string type_text;      ///< the descr as written, for messages
};

struct NpyHeader {
  int major = 0;
  std::int64_t data_offset = 0;  ///< where the records begin
  bool fortran_order = false;
  std::vector<std::int64_t> shape;
  std::size_t record_bytes = 0;  ///< one element (a structured record, or one scalar)
  /// A plain array's element type; empty for a structured dtype.
  std::optional<NpyScalar> scalar;
  std::string scalar_text;       ///< the plain descr as written ('<f8'), for messages
  std::vector<NpyField> fields;  ///< a structured dtype's fields, in order
};

/// What parsing the header found: the header, or why it is not one (with the
/// byte offset of the fault).
struct NpyHeaderResult {
  std::optional<NpyHeader> header;
  std::string why;
  std::int64_t offset = 0;
  /// The header is longer than `head` holds: read this many bytes and retry.
  std::size_t needs_bytes = 0;
};

/// Parses the header from the first bytes of a file. Never throws.
NpyHeaderResult parse_npy_header(std::span<const std::byte> head);

/// The shape as Python writes it: "(200,)", "(200, 4)".
std::string npy_shape_text(const NpyHeader& h);

/// Parses one scalar type string ('<i8'); empty when evlife does not read it.
std::optional<NpyScalar> parse_npy_scalar(const std::string& text);

}  // namespace evlife::io::detail
