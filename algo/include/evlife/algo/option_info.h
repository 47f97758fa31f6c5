// One declaration of a numeric option: its configuration key, command-line
// flag, allowed range and one line of documentation. Option structs list
// theirs next to their fields (lifetime_options.h, engine_options.h) through a
// for_each_*_option(f) function that calls f(info, field accessor) per field;
// validation, the YAML keys (config/), the command-line flags and the --help
// text are all read from it, so a range is written once.
#pragma once

#include <charconv>
#include <cmath>
#include <cstdio>
#include <string>
#include <string_view>
#include <type_traits>

namespace evlife {

struct OptionInfo {
  std::string_view key;    ///< YAML key below its section, e.g. "window_size"
  std::string_view flag;   ///< command-line flag without dashes ("" = none)
  double lo = 0.0;         ///< lower bound (excluded when lo_open)
  double hi = 0.0;         ///< upper bound (excluded when hi_open)
  bool lo_open = false;
  bool hi_open = false;
  bool odd = false;        ///< integers only: must be odd
  bool auto_minus_one = false;  ///< -1 also allowed, meaning "automatic"
  std::string_view doc;    ///< one line for --help and the configuration file

  constexpr bool contains(double v) const noexcept {
    if (auto_minus_one && v == -1.0) return true;
    if (!(v == v)) return false;  // NaN
    const bool lo_ok = lo_open ? v > lo : v >= lo;
    const bool hi_ok = hi_open ? v < hi : v <= hi;
    if (!lo_ok || !hi_ok) return false;  // before the cast: 1e23 is no long long
    return !odd || static_cast<long long>(v) % 2 != 0;
  }

  /// "odd, [3, 15]", "-1 (auto) or [0, 1024]", "(0, 0.9]".
  std::string range_text() const { return (odd ? "odd, " : "") + bounds_text(); }

  /// range_text() without "odd, ": "[3, 15]".
  std::string bounds_text() const {
    auto num = [](double v) {
      char buf[32];
      if (v == 18446744073709551615.0) return std::string("18446744073709551615");  // a uint64's whole range (2^64 as a double)
      if (v == std::floor(v) && std::fabs(v) < 1e15)
        std::snprintf(buf, sizeof buf, "%.0f", v);
      else
        std::snprintf(buf, sizeof buf, "%g", v);
      return std::string(buf);
    };
    std::string s;
    if (auto_minus_one) s += "-1 (auto) or ";
    s.append(lo_open ? "(" : "[").append(num(lo)).append(", ").append(num(hi));
    s.append(hi_open ? ")" : "]");
    return s;
  }
};

/// An option's value as given: integers in digits, floating values in the
/// shortest text that reads back as the value (std::to_string's six decimals
/// showed 0.9000001 as "0.900000", inside the "(0, 0.9]" beside it).
template <typename T>
std::string option_value_text(T v) {
  if constexpr (std::is_floating_point_v<T>) {
    char buf[32];
    return std::string(buf, std::to_chars(buf, buf + sizeof buf, v).ptr);
  } else {
    return std::to_string(v);
  }
}

/// "<key>: <value> must be in <range>" ("must be odd, in [3, 15]"), or ""
/// when `v` is allowed.
template <typename T>
std::string check_option(const OptionInfo& info, T v) {
  if (info.contains(static_cast<double>(v))) return {};
  return std::string(info.key) + ": " + option_value_text(v) + (info.odd ? " must be odd, in " : " must be in ") +
         info.bounds_text();
}

}  // namespace evlife
