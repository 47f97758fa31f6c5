// The key table (one add_<section>_keys per section) and strict scalar parsing:
// a value must be entirely a number/boolean of the key's type, no leftovers.
#include "evlife/config/config_key.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <string>

#include "evlife/algo/parse_text.h"
#include "key_helpers.h"

namespace evlife::config {

const std::vector<ConfigKey>& config_keys() {
  static const std::vector<ConfigKey> keys = [] {
    std::vector<ConfigKey> k;
    detail::add_estimator_keys(k);
    detail::add_engine_keys(k);
    // New sections: detail::add_<section>_keys(k);
    return k;
  }();
  return keys;
}

const ConfigKey* find_config_key(std::string_view name) {
  for (const auto& k : config_keys()) {
    if (k.name == name) return &k;
  }
  return nullptr;
}

namespace detail {

bool parse_bool(std::string_view text, bool& out) {
  if (text == "true" || text == "True" || text == "TRUE") {
    out = true;
    return true;
  }
  if (text == "false" || text == "False" || text == "FALSE") {
    out = false;
    return true;
  }
  return false;
}

bool parse_double(std::string_view text, double& out) {
  const auto v = parse_decimal(text);  // the one number parser (algo/)
  if (v) out = *v;
  return v.has_value();
}

namespace {
// Removes a "0x" / "0X" prefix that is followed by something, where `hex`.
bool remove_hex_prefix(std::string_view& text, bool hex) {
  if (!hex || text.size() <= 2 || text[0] != '0' || (text[1] != 'x' && text[1] != 'X')) return false;
  text.remove_prefix(2);
  return true;
}

// Decimal, or 0x-prefixed hexadecimal where `hex`; whole text.
template <typename T>
bool parse_integer(std::string_view text, T& out, bool hex) {
  const bool plus = !text.empty() && text.front() == '+';  // one sign at most: "+-1" is no number
  if (plus) text.remove_prefix(1);
  bool negative = false;
  if (!plus && !text.empty() && text.front() == '-') {
    negative = true;
    text.remove_prefix(1);
  }
  const int base = remove_hex_prefix(text, hex) ? 16 : 10;
  if (text.empty() || text.front() == '-' || text.front() == '+') return false;
  const char* end = text.data() + text.size();
  T v{};
  auto [ptr, ec] = std::from_chars(text.data(), end, v, base);
  if (ec != std::errc() || ptr != end) return false;
  if (negative) {
    if constexpr (std::is_unsigned_v<T>) {
      if (v != 0) return false;
    } else {
      v = -v;
    }
  }
  out = v;
  return true;
}
}  // namespace

bool parse_int64(std::string_view text, long long& out) { return parse_integer(text, out, /*hex=*/false); }

bool is_integer_text(std::string_view text, bool hex) {
  std::string_view digits = text;
  if (!digits.empty() && (digits.front() == '+' || digits.front() == '-')) digits.remove_prefix(1);
  if (!remove_hex_prefix(digits, hex)) return is_decimal_integer(text);  // the flags' rule (parse_text.h)
  return !digits.empty() && std::all_of(digits.begin(), digits.end(), [](char c) {
    return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F');
  });
}
bool parse_uint64(std::string_view text, unsigned long long& out, bool hex) {
  return parse_integer(text, out, hex);
}

std::string format_double(double v) {
  char buf[64];
  auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, v);  // shortest round-trip form
  if (ec != std::errc()) return "nan";
  return std::string(buf, ptr);
}

}  // namespace detail
}  // namespace evlife::config
