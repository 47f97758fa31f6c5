#include "evlife/algo/parse_text.h"

#include <charconv>
#include <cmath>

namespace evlife {

std::optional<double> parse_decimal(std::string_view text) noexcept {
  // One sign at most: "+-1" and "++1" are no numbers (from_chars takes a '-' but no '+').
  if (!text.empty() && text.front() == '+') {
    text.remove_prefix(1);
    if (!text.empty() && text.front() == '-') return std::nullopt;
  }
  if (text.empty() || text.front() == '+') return std::nullopt;
  double v = 0.0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, v);
  if (ec != std::errc() || ptr != end || !std::isfinite(v)) return std::nullopt;
  return v;
}

bool is_decimal_integer(std::string_view text) noexcept {
  if (!text.empty() && (text.front() == '+' || text.front() == '-')) text.remove_prefix(1);
  if (text.empty()) return false;
  for (const char c : text)
    if (c < '0' || c > '9') return false;
  return true;
}

std::optional<std::int64_t> parse_time_us(std::string_view text) noexcept {
  std::string_view number = text;
  double unit_us = 1e6;
  auto ends_with = [&](std::string_view suffix) {
    return number.size() > suffix.size() && number.substr(number.size() - suffix.size()) == suffix;
  };
  if (ends_with("us")) {
    unit_us = 1.0;
    number.remove_suffix(2);
  } else if (ends_with("ms")) {
    unit_us = 1e3;
    number.remove_suffix(2);
  } else if (ends_with("s")) {
    number.remove_suffix(1);
  }
  const auto value = parse_decimal(number);
  if (!value || *value < 0.0 || *value * unit_us > 1e15) return std::nullopt;
  const std::int64_t us = std::llround(*value * unit_us);
  // A positive time under half a microsecond is no time the clock holds: as
  // 0 it would mean "none" to the keys where 0 turns a feature off.
  if (us == 0 && *value > 0.0) return std::nullopt;
  return us;
}

}  // namespace evlife
