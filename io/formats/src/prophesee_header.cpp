#include "prophesee_header.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstring>

#include "chunked_file.h"
#include "evlife/io/event_reader.h"

namespace evlife::io {
namespace {

constexpr std::size_t kMaxLineBytes = 64 * 1024;

bool iequals(std::string_view a, std::string_view b) {
  return a.size() == b.size() &&
         std::equal(a.begin(), a.end(), b.begin(), [](char c1, char c2) {
           return std::tolower(static_cast<unsigned char>(c1)) ==
                  std::tolower(static_cast<unsigned char>(c2));
         });
}

std::string_view trim_view(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

std::optional<int> to_int(std::string_view s) {
  s = trim_view(s);
  int v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || v <= 0 || v > 1 << 16) return std::nullopt;
  return v;
}

// `line` without the leading '%' and the newline; false for `% end`.
bool add_line(PropheseeHeader& header, std::string_view line) {
  line = trim_view(line);
  if (iequals(line, "end")) return false;
  const std::size_t space = line.find_first_of(" \t");
  std::string_view key = line.substr(0, space);
  std::string_view value = space == std::string_view::npos ? std::string_view{} : line.substr(space);
  header.fields.emplace_back(std::string(key), std::string(trim_view(value)));
  return true;
}

// Value of `name=` inside a `;`-separated format string, e.g. "EVT3;height=720;width=1280".
std::optional<std::string_view> format_option(std::string_view format, std::string_view name) {
  std::size_t pos = 0;
  while (pos <= format.size()) {
    const std::size_t next = std::min(format.find(';', pos), format.size());
    const std::string_view item = format.substr(pos, next - pos);
    const std::size_t eq = item.find('=');
    if (eq != std::string_view::npos && iequals(trim_view(item.substr(0, eq)), name)) {
      return item.substr(eq + 1);
    }
    pos = next + 1;
  }
  return std::nullopt;
}

}  // namespace

std::optional<std::string_view> PropheseeHeader::find(std::string_view key) const {
  for (const auto& [k, v] : fields) {
    if (iequals(k, key)) return std::string_view(v);
  }
  return std::nullopt;
}

std::string PropheseeHeader::evt_version() const {
  if (auto evt = find("evt")) return std::string(trim_view(*evt));
  if (auto format = find("format")) {
    const std::string_view name = format->substr(0, format->find(';'));
    if (iequals(name, "EVT2")) return "2.0";
    if (iequals(name, "EVT21")) return "2.1";
    if (iequals(name, "EVT3")) return "3.0";
  }
  // Older RAW files name only the camera plugin; its sensor fixes the format.
  if (auto plugin = find("plugin_name")) {
    const std::string p(*plugin);
    if (p.find("gen3") != std::string::npos) return "2.0";  // gen3, gen31
    if (p.find("gen4") != std::string::npos || p.find("imx636") != std::string::npos) return "3.0";
  }
  return {};
}

std::optional<SensorSize> PropheseeHeader::sensor_size() const {
  if (auto geometry = find("geometry")) {  // "640x480" or "640 480"
    const std::size_t sep = geometry->find_first_of("x \t");
    if (sep != std::string_view::npos) {
      auto w = to_int(geometry->substr(0, sep));
      auto h = to_int(geometry->substr(sep + 1));
      if (w && h) return SensorSize{*w, *h};
    }
  }
  if (auto format = find("format")) {
    auto w = format_option(*format, "width");
    auto h = format_option(*format, "height");
    if (w && h && to_int(*w) && to_int(*h)) return SensorSize{*to_int(*w), *to_int(*h)};
  }
  auto width = find("width");
  auto height = find("height");
  if (width && height && to_int(*width) && to_int(*height)) {
    return SensorSize{*to_int(*width), *to_int(*height)};
  }
  // Older RAW files name only the camera plugin; the sensor follows from it.
  if (auto plugin = find("plugin_name")) {
    const std::string p(*plugin);
    if (p.find("gen41") != std::string::npos || p.find("imx636") != std::string::npos ||
        p.find("gen4") != std::string::npos) {
      return SensorSize{1280, 720};
    }
    if (p.find("gen31") != std::string::npos || p.find("gen3") != std::string::npos) {
      return SensorSize{640, 480};
    }
    if (p.find("genx320") != std::string::npos) return SensorSize{320, 320};
  }
  return std::nullopt;
}

PropheseeHeader read_prophesee_header(ChunkedFile& file) {
  PropheseeHeader header;
  while (true) {
    if (file.fill(1) == 0 || file.data()[0] != '%') break;
    const std::int64_t line_offset = file.offset();
    file.fill(kMaxLineBytes);
    const auto* begin = file.data();
    const auto* newline = static_cast<const std::uint8_t*>(std::memchr(begin, '\n', file.available()));
    if (newline == nullptr) {
      if (file.available() >= kMaxLineBytes) {
        throw ReadError(file.path(), line_offset, -1, "header line longer than 64 KiB");
      }
      throw ReadError(file.path(), line_offset, -1, "file ends inside the '%' header");
    }
    const std::size_t length = static_cast<std::size_t>(newline - begin);
    const bool more = add_line(header, std::string_view(reinterpret_cast<const char*>(begin) + 1, length - 1));
    file.consume(length + 1);
    if (!more) break;
  }
  header.size_bytes = file.offset();
  return header;
}

std::optional<PropheseeHeader> parse_prophesee_header(std::span<const std::byte> head) {
  if (head.empty() || head[0] != std::byte{'%'}) return std::nullopt;
  PropheseeHeader header;
  const char* text = reinterpret_cast<const char*>(head.data());
  std::size_t pos = 0;
  while (pos < head.size() && text[pos] == '%') {
    const void* nl = std::memchr(text + pos, '\n', head.size() - pos);
    if (nl == nullptr) return header;  // header longer than `head`: what we have
    const std::size_t end = static_cast<std::size_t>(static_cast<const char*>(nl) - text);
    const bool more = add_line(header, std::string_view(text + pos + 1, end - pos - 1));
    pos = end + 1;
    if (!more) break;
  }
  header.size_bytes = static_cast<std::int64_t>(pos);
  return header;
}

}  // namespace evlife::io
