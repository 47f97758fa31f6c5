#include "evlife/io/dvs128_biases.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace evlife::io {

std::array<std::uint8_t, 3 * Dvs128Biases::kCount> Dvs128Biases::to_bytes() const noexcept {
  std::array<std::uint8_t, 3 * kCount> bytes{};
  for (std::size_t i = 0; i < values.size(); ++i) {
    const std::uint32_t v = values[i] & kMax;
    bytes[3 * i + 0] = static_cast<std::uint8_t>(v >> 16);
    bytes[3 * i + 1] = static_cast<std::uint8_t>(v >> 8);
    bytes[3 * i + 2] = static_cast<std::uint8_t>(v);
  }
  return bytes;
}

namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

bool iequals(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) ==
                  std::tolower(static_cast<unsigned char>(y));
         });
}

}  // namespace

// A deliberately small reader (flat `key: integer` YAML) so that io/ needs no
// YAML library; anything else in the file is an error, not silently ignored.
Dvs128Biases Dvs128Biases::load_file(const std::string& path) {
  std::error_code no_stat;  // a path that cannot be examined is left to the open below
  if (std::filesystem::is_directory(path, no_stat))  // opens, and reads as empty: all defaults, unsaid
    throw std::runtime_error(path + ": a directory, not a DVS128 bias file");
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open the DVS128 bias file");
  Dvs128Biases biases;
  std::string line;
  int line_no = 0;
  auto fail = [&](const std::string& why) {
    throw std::runtime_error(path + ":" + std::to_string(line_no) + ": " + why);
  };
  while (std::getline(in, line)) {
    ++line_no;
    std::string_view s = line;
    if (const auto hash = s.find('#'); hash != std::string_view::npos) s = s.substr(0, hash);
    s = trim(s);
    if (s.empty() || s == "---") continue;
    const auto colon = s.find(':');
    if (colon == std::string_view::npos) fail("expected `name: value`, got '" + std::string(s) + "'");
    const std::string_view key = trim(s.substr(0, colon));
    const std::string_view value = trim(s.substr(colon + 1));
    if (iequals(key, "dvs128_biases") && value.empty()) continue;  // optional top-level map key
    const auto it = std::find_if(kNames.begin(), kNames.end(),
                                 [&](std::string_view n) { return iequals(n, key); });
    if (it == kNames.end()) {
      std::string known;
      for (auto n : kNames) known += (known.empty() ? "" : ", ") + std::string(n);
      fail("unknown bias '" + std::string(key) + "' (known: " + known + ")");
    }
    std::uint64_t v = 0;
    const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), v);
    if (ec != std::errc() || end != value.data() + value.size() || v > kMax) {
      fail("bias '" + std::string(key) + "' must be an integer 0..16777215, got '" +
           std::string(value) + "'");
    }
    biases.values[static_cast<std::size_t>(it - kNames.begin())] = static_cast<std::uint32_t>(v);
  }
  if (in.bad()) fail("read error");
  return biases;
}

}  // namespace evlife::io
