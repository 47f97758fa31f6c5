#include <string>

#include "evlife/io/event_reader.h"
#include "evlife/io/stream_copy_name.h"

namespace evlife::io {
namespace {

// Length of the valid UTF-8 sequence at `s[i]` (a character of a path or of
// the message's own text), 0 when the bytes there are none.
std::size_t utf8_length(const std::string& s, std::size_t i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char lead = byte(i);
  const std::size_t n = lead < 0x80 ? 1 : (lead >> 5) == 0x6 ? 2 : (lead >> 4) == 0xE ? 3 : (lead >> 3) == 0x1E ? 4 : 0;
  if (n == 0 || i + n > s.size()) return 0;
  for (std::size_t k = 1; k < n; ++k) {
    if ((byte(i + k) >> 6) != 0x2) return 0;
  }
  return n;
}

// The message as text a terminal and Python's str take whole: a corrupt file
// quoted into it (a NUL would end it early for printf, a stray byte fail
// UTF-8 decoding) has its control bytes (but newlines and tabs) and non-UTF-8
// bytes written as \xNN.
std::string printable(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size();) {
    const std::size_t n = utf8_length(s, i);
    const auto c = static_cast<unsigned char>(s[i]);
    const bool layout = c == '\n' || c == '\t';  // the message's own lines (a list of formats)
    if (n == 0 || (n == 1 && !layout && (c < 0x20 || c == 0x7F))) {
      static constexpr char kHex[] = "0123456789abcdef";
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 0xF];
      ++i;
    } else {
      out.append(s, i, n);
      i += n;
    }
  }
  return out;
}

// "<path>: <what> (event index N, byte offset B)" — where parts are known.
std::string compose(const std::string& path, std::int64_t byte_offset, std::int64_t event_index,
                    const std::string& what) {
  std::string message = path + ": " + what;
  if (event_index >= 0 || byte_offset >= 0) {
    message += " (";
    if (event_index >= 0) message += "event index " + std::to_string(event_index);
    if (event_index >= 0 && byte_offset >= 0) message += ", ";
    if (byte_offset >= 0) message += "byte offset " + std::to_string(byte_offset);
    message += ")";
  }
  return message;
}

}  // namespace

// The file as the user gave it: a stream's temporary copy is named after the
// stream (`stdin`, the pipe's path), in what() and path() alike.
ReadError::ReadError(const std::string& path, std::int64_t byte_offset, std::int64_t event_index,
                     const std::string& what)
    : std::runtime_error(printable(compose(name_in_messages(path), byte_offset, event_index, what))),
      path_(name_in_messages(path)),
      reason_(printable(what)),
      byte_offset_(byte_offset),
      event_index_(event_index) {}

}  // namespace evlife::io
