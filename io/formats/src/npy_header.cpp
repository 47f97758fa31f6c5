#include "npy_header.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <string_view>
#include <tuple>
#include <utility>

namespace evlife::io::detail {
namespace {

constexpr int kMaxDepth = 16;
constexpr std::size_t kMaxSizedRecordBytes = std::size_t{1} << 30;

/// A value of the Python literal subset numpy's headers use.
struct PyValue {
  enum class Kind { string, integer, boolean, none, sequence, dict } kind = Kind::none;
  std::string text;                   // string
  std::int64_t integer = 0;           // integer
  bool boolean = false;               // boolean
  std::vector<PyValue> items;         // sequence (tuple or list); dict values
  std::vector<std::string> keys;      // dict keys (strings), parallel to items
};

class LiteralParser {
 public:
  explicit LiteralParser(std::string_view text) : text_(text) {}

  /// The whole text as one value (trailing blanks allowed); empty on error.
  std::optional<PyValue> parse_all() {
    PyValue v;
    if (!value(v, 0)) return std::nullopt;
    skip_blanks();
    if (pos_ != text_.size()) {
      fail("unexpected text after the dict");
      return std::nullopt;
    }
    return v;
  }
  const std::string& why() const noexcept { return why_; }
  std::size_t pos() const noexcept { return pos_; }

 private:
  /// Records the first fault; false, for `return fail(...)`.
  bool fail(const char* why) {
    if (why_.empty()) why_ = why;
    return false;
  }
  void skip_blanks() {
    while (pos_ < text_.size() && (text_[pos_] == ' ' || text_[pos_] == '\t' || text_[pos_] == '\n' ||
                                   text_[pos_] == '\r'))
      ++pos_;
  }
  bool eat(char c) {
    skip_blanks();
    if (pos_ < text_.size() && text_[pos_] == c) {
      ++pos_;
      return true;
    }
    return false;
  }
  bool starts_with(std::string_view word) const { return text_.substr(pos_).starts_with(word); }

  bool value(PyValue& v, int depth) {
    if (depth > kMaxDepth) return fail("nested too deeply");
    skip_blanks();
    if (pos_ >= text_.size()) return fail("the header ends inside a value");
    const char c = text_[pos_];
    if (c == '\'' || c == '"') return string(v);
    if (c == '-' || (c >= '0' && c <= '9')) return integer(v);
    if (c == '(' || c == '[') return sequence(v, c == '(' ? ')' : ']', depth);
    if (c == '{') return dict(v, depth);
    for (const auto& [word, kind, b] : {std::tuple{"True", PyValue::Kind::boolean, true},
                                        std::tuple{"False", PyValue::Kind::boolean, false},
                                        std::tuple{"None", PyValue::Kind::none, false}}) {
      if (starts_with(word)) {
        pos_ += std::strlen(word);
        v.kind = kind;
        v.boolean = b;
        return true;
      }
    }
    return fail("not a Python literal numpy writes");
  }

  bool string(PyValue& v) {
    const char quote = text_[pos_++];
    v.kind = PyValue::Kind::string;
    while (pos_ < text_.size() && text_[pos_] != quote) {
      char c = text_[pos_++];
      if (c == '\\' && pos_ < text_.size()) c = text_[pos_++];  // \' \" \\ (others kept as the character)
      v.text.push_back(c);
    }
    if (pos_ >= text_.size()) return fail("a string is not closed");
    ++pos_;
    return true;
  }

  bool integer(PyValue& v) {
    const bool negative = text_[pos_] == '-';
    if (negative) ++pos_;
    std::uint64_t n = 0;
    const std::size_t begin = pos_;
    while (pos_ < text_.size() && text_[pos_] >= '0' && text_[pos_] <= '9') {
      const auto digit = static_cast<std::uint64_t>(text_[pos_] - '0');
      if (n > (static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()) - digit) / 10)
        return fail("an integer is too large");
      n = n * 10 + digit;
      ++pos_;
    }
    if (pos_ == begin) return fail("a '-' without digits");
    if (pos_ < text_.size() && text_[pos_] == 'L') ++pos_;  // Python 2's long: (10L,)
    v.kind = PyValue::Kind::integer;
    v.integer = negative ? -static_cast<std::int64_t>(n) : static_cast<std::int64_t>(n);
    return true;
  }

  bool sequence(PyValue& v, char close, int depth) {
    ++pos_;
    v.kind = PyValue::Kind::sequence;
    while (!eat(close)) {
      if (!v.items.empty() && !eat(',')) return fail("expected ',' between items");
      if (eat(close)) break;  // a trailing comma
      PyValue item;
      if (!value(item, depth + 1)) return false;
      v.items.push_back(std::move(item));
    }
    return true;
  }

  bool dict(PyValue& v, int depth) {
    ++pos_;
    v.kind = PyValue::Kind::dict;
    while (!eat('}')) {
      if (!v.items.empty() && !eat(',')) return fail("expected ',' between dict entries");
      if (eat('}')) break;
      PyValue key;
      if (!value(key, depth + 1)) return false;
      if (key.kind != PyValue::Kind::string) return fail("a dict key is not a string");
      if (!eat(':')) return fail("expected ':' after a dict key");
      PyValue item;
      if (!value(item, depth + 1)) return false;
      v.keys.push_back(std::move(key.text));
      v.items.push_back(std::move(item));
    }
    return true;
  }

  std::string_view text_;
  std::size_t pos_ = 0;
  std::string why_;
};

const PyValue* lookup(const PyValue& dict, std::string_view key) {
  for (std::size_t i = 0; i < dict.keys.size(); ++i)
    if (dict.keys[i] == key) return &dict.items[i];
  return nullptr;
}

/// A numpy type string taken apart: '<M8[us]' is order '<', kind 'M', count
/// 8, unit "us" (the one grammar of both readings below).
struct TypeString {
  char order = '|';
  char kind = 0;
  std::size_t count = 0;  ///< bytes, or characters ('U', 'S')
  std::string unit;       ///< datetime64's, in brackets
};

std::optional<TypeString> split_type(const std::string& text) {
  TypeString t;
  std::size_t i = 0;
  if (i < text.size() && (text[i] == '<' || text[i] == '>' || text[i] == '|' || text[i] == '=')) t.order = text[i++];
  if (i >= text.size()) return std::nullopt;
  t.kind = text[i++];
  const std::size_t digits_at = i;
  while (i < text.size() && text[i] >= '0' && text[i] <= '9' && t.count < kMaxSizedRecordBytes)
    t.count = t.count * 10 + static_cast<std::size_t>(text[i++] - '0');
  if (i == digits_at || t.count >= kMaxSizedRecordBytes) return std::nullopt;
  if (i < text.size()) {
    if (text[i] != '[' || text.back() != ']') return std::nullopt;
    t.unit = text.substr(i + 1, text.size() - i - 2);
  }
  return t;
}

/// Bytes of one element of any type string numpy writes ('<U10' holds 10
/// UCS-4 characters; 0 is a size, of a zero-length field); empty for an
/// unknown one, or Python objects ('|O').
std::optional<std::size_t> type_bytes(const std::string& text) {
  const std::optional<TypeString> t = split_type(text);
  if (!t) return std::nullopt;
  switch (t->kind) {
    case 'b': case 'i': case 'u': case 'f': case 'c': case 'S': case 'a': case 'V': case 'M': case 'm':
      return t->count;
    case 'U':
      return t->count * 4;
    default:
      return std::nullopt;
  }
}

/// The size of a field's type: a type string, or a nested structured list;
/// `shape` (a sub-array) multiplies it. Empty when unknown.
std::optional<std::size_t> descr_bytes(const PyValue& type, const PyValue* shape, int depth);

std::optional<std::size_t> list_bytes(const PyValue& list, int depth) {
  if (depth > kMaxDepth) return std::nullopt;
  std::size_t total = 0;
  for (const PyValue& field : list.items) {
    if (field.kind != PyValue::Kind::sequence || field.items.size() < 2 || field.items.size() > 3) return std::nullopt;
    const std::optional<std::size_t> bytes =
        descr_bytes(field.items[1], field.items.size() == 3 ? &field.items[2] : nullptr, depth + 1);
    if (!bytes || total + *bytes > kMaxSizedRecordBytes) return std::nullopt;
    total += *bytes;
  }
  return total;
}

std::optional<std::size_t> descr_bytes(const PyValue& type, const PyValue* shape, int depth) {
  std::optional<std::size_t> bytes = type.kind == PyValue::Kind::string     ? type_bytes(type.text)
                                     : type.kind == PyValue::Kind::sequence ? list_bytes(type, depth)
                                                                            : std::nullopt;
  if (shape == nullptr || !bytes) return bytes;
  const auto one = [&bytes](const PyValue& dim) {
    if (dim.kind != PyValue::Kind::integer || dim.integer < 0 ||
        (dim.integer > 0 && *bytes > kMaxSizedRecordBytes / static_cast<std::size_t>(dim.integer)))
      return false;
    *bytes *= static_cast<std::size_t>(dim.integer);
    return true;
  };
  if (shape->kind == PyValue::Kind::integer) return one(*shape) ? bytes : std::nullopt;
  if (shape->kind != PyValue::Kind::sequence) return std::nullopt;
  for (const PyValue& dim : shape->items)
    if (!one(dim)) return std::nullopt;
  return bytes;
}

/// numpy writes version 1 and 2 headers in Latin-1 (a field named 't (µs)'
/// holds the byte 0xB5), version 3 in UTF-8: the text as UTF-8.
std::string header_text_as_utf8(std::string_view text, int major) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    const auto b = static_cast<unsigned char>(c);
    if (major >= 3 || b < 0x80) {
      out.push_back(c);
    } else {
      out.push_back(static_cast<char>(0xC0 | (b >> 6)));
      out.push_back(static_cast<char>(0x80 | (b & 0x3F)));
    }
  }
  return out;
}

std::string field_name(const PyValue& name) {
  // (title, name) pairs: numpy's titles; the name is the second.
  if (name.kind == PyValue::Kind::sequence && name.items.size() == 2) return field_name(name.items[1]);
  return name.kind == PyValue::Kind::string ? name.text : std::string{};
}

}  // namespace

std::string npy_shape_text(const NpyHeader& h) {
  std::string text;
  for (const std::int64_t d : h.shape) text += (text.empty() ? "" : ", ") + std::to_string(d);
  return "(" + text + (h.shape.size() == 1 ? ",)" : ")");
}

std::optional<NpyScalar> parse_npy_scalar(const std::string& text) {
  const std::optional<TypeString> t = split_type(text);
  if (!t || (t->count != 1 && t->count != 2 && t->count != 4 && t->count != 8)) return std::nullopt;
  NpyScalar s;
  s.big_endian = t->order == '>';
  s.kind = t->kind;
  s.bytes = t->count;
  const std::string& unit = t->unit;
  switch (s.kind) {
    case 'b':
      if (s.bytes != 1 || !unit.empty()) return std::nullopt;
      break;
    case 'i': case 'u':
      if (!unit.empty()) return std::nullopt;
      break;
    case 'f':
      if ((s.bytes != 4 && s.bytes != 8) || !unit.empty()) return std::nullopt;
      break;
    case 'M':
      if (s.bytes != 8) return std::nullopt;
      if (unit == "s") s.unit_ns = 1'000'000'000;
      else if (unit == "ms") s.unit_ns = 1'000'000;
      else if (unit == "us") s.unit_ns = 1'000;
      else if (unit == "ns") s.unit_ns = 1;
      else return std::nullopt;
      break;
    default:
      return std::nullopt;
  }
  return s;
}

NpyHeaderResult parse_npy_header(std::span<const std::byte> head) {
  NpyHeaderResult r;
  const auto byte = [&head](std::size_t i) { return static_cast<unsigned char>(head[i]); };
  if (head.empty() || std::memcmp(head.data(), kNpyMagic, std::min(head.size(), kNpyMagicBytes)) != 0) {
    r.why = "no .npy magic (\\x93NUMPY)";
    return r;
  }
  if (head.size() < 10) {
    r.needs_bytes = 10;
    r.why = "the file ends inside its header";
    r.offset = static_cast<std::int64_t>(head.size());
    return r;
  }
  NpyHeader h;
  h.major = byte(6);
  if (h.major < 1 || h.major > 3) {
    r.why = "format version " + std::to_string(h.major) + "." + std::to_string(byte(7)) + " (1.0 to 3.0 are read)";
    r.offset = 6;
    return r;
  }
  const std::size_t length_at = 8;
  const std::size_t length_bytes = h.major == 1 ? 2 : 4;
  if (head.size() < length_at + length_bytes) {
    r.needs_bytes = length_at + length_bytes;
    r.why = "the file ends inside its header";
    return r;
  }
  std::size_t header_len = 0;
  for (std::size_t i = 0; i < length_bytes; ++i) header_len |= static_cast<std::size_t>(byte(length_at + i)) << (8 * i);
  if (header_len > kNpyMaxHeaderBytes) {
    r.why = "a header of " + std::to_string(header_len) + " bytes (at most 1 MiB is read)";
    r.offset = static_cast<std::int64_t>(length_at);
    return r;
  }
  const std::size_t text_at = length_at + length_bytes;
  h.data_offset = static_cast<std::int64_t>(text_at + header_len);
  if (head.size() < text_at + header_len) {
    r.needs_bytes = text_at + header_len;
    r.why = "the file ends inside its header";
    r.offset = static_cast<std::int64_t>(head.size());
    return r;
  }
  const std::string text =
      header_text_as_utf8({reinterpret_cast<const char*>(head.data()) + text_at, header_len}, h.major);
  LiteralParser parser(text);
  const std::optional<PyValue> dict = parser.parse_all();
  const auto fail = [&](std::string why, std::size_t at) {
    r.why = "header: " + std::move(why);
    r.offset = static_cast<std::int64_t>(text_at + at);
    return r;
  };
  if (!dict) return fail(parser.why(), parser.pos());
  if (dict->kind != PyValue::Kind::dict) return fail("not a dict", 0);
  const PyValue* descr = lookup(*dict, "descr");
  const PyValue* fortran = lookup(*dict, "fortran_order");
  const PyValue* shape = lookup(*dict, "shape");
  if (descr == nullptr || fortran == nullptr || shape == nullptr)
    return fail("it lacks 'descr', 'fortran_order' or 'shape'", 0);
  if (fortran->kind != PyValue::Kind::boolean) return fail("'fortran_order' is not True or False", 0);
  h.fortran_order = fortran->boolean;
  if (shape->kind != PyValue::Kind::sequence) return fail("'shape' is not a tuple", 0);
  for (const PyValue& dim : shape->items) {
    if (dim.kind != PyValue::Kind::integer || dim.integer < 0) return fail("'shape' holds a negative or non-integer size", 0);
    h.shape.push_back(dim.integer);
  }
  if (descr->kind == PyValue::Kind::string) {
    h.scalar_text = descr->text;
    h.scalar = parse_npy_scalar(descr->text);
    const std::optional<std::size_t> bytes = type_bytes(descr->text);
    if (!bytes || *bytes == 0) return fail("the type '" + descr->text + "' (Python objects or unknown)", 0);
    h.record_bytes = *bytes;
  } else if (descr->kind == PyValue::Kind::sequence) {
    std::size_t offset = 0;
    for (const PyValue& f : descr->items) {
      if (f.kind != PyValue::Kind::sequence || f.items.size() < 2 || f.items.size() > 3)
        return fail("a field of 'descr' is not (name, type[, shape])", 0);
      const std::optional<std::size_t> bytes =
          descr_bytes(f.items[1], f.items.size() == 3 ? &f.items[2] : nullptr, 1);
      if (!bytes) return fail("a field's type is one evlife cannot size (Python objects?)", 0);
      NpyField field;
      field.name = field_name(f.items[0]);
      field.offset = offset;
      if (f.items[1].kind == PyValue::Kind::string) {
        field.type_text = f.items[1].text;
        if (f.items.size() == 2) field.scalar = parse_npy_scalar(f.items[1].text);
      } else {
        field.type_text = "a nested structure";
      }
      if (f.items.size() == 3) field.type_text += " (a sub-array)";
      offset += *bytes;
      if (offset > kMaxSizedRecordBytes) return fail("records of more than 1 GiB", 0);
      h.fields.push_back(std::move(field));
    }
    if (h.fields.empty() || offset == 0) return fail("a structured type without fields or bytes", 0);
    h.record_bytes = offset;
  } else {
    return fail("'descr' is neither a type string nor a list of fields", 0);
  }
  r.header = std::move(h);
  return r;
}

}  // namespace evlife::io::detail
