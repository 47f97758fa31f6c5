// Decimal numbers in event text files, parsed exactly (no floating point):
// sign, digits, an optional fraction and an optional exponent, so that what
// NumPy's savetxt writes by default ("1.000000000000000000e+00",
// "9.999999999999999547e-07") reads as the integers and seconds it holds.
#pragma once

#include <cstdint>

namespace evlife::io::detail {

/// '0'..'9' (no locale: std::isdigit's reads the C locale's table).
inline bool is_decimal_digit(char c) noexcept { return c >= '0' && c <= '9'; }

struct DecimalNumber {
  bool negative = false;
  std::uint64_t int_part = 0;  // the digits before the point, exponent applied
  std::uint64_t frac = 0;      // the first up to 9 fraction digits
  int frac_digits = 0;         // how many of them (9 when an exponent moved the point)
  bool round_up = false;       // the 10th fraction digit >= 5
  bool has_point = false;      // written with a '.'
  bool has_exponent = false;   // written with e/E
  bool integral = true;        // no non-zero fraction digit
};

/// Parses [begin, end) whole; false when it is not a number or the integer
/// part exceeds 19 digits (epoch ns of ROS exports fit).
bool parse_decimal(const char* begin, const char* end, DecimalNumber& n) noexcept;

/// A time written as a fraction of its unit ("0.5", "12.000", "1.5e-06"), not
/// as a count ("12", or "1.2e+01" as savetxt writes integers): the rule that
/// tells seconds from µs in a file without a unit.
inline bool written_as_fraction(const DecimalNumber& n) noexcept {
  return (n.has_point && !n.has_exponent) || !n.integral;
}

/// An integral value in [0, max] ("12", "12.0", "1.2e+01"), for coordinates.
inline bool as_uint(const DecimalNumber& n, std::uint64_t max, std::uint64_t& v) noexcept {
  if (n.negative || !n.integral || n.int_part > max) return false;
  v = n.int_part;
  return true;
}

/// a < b as written (their first 9 fraction digits): no unit, no overflow.
inline bool decimal_less(const DecimalNumber& a, const DecimalNumber& b) noexcept {
  const auto frac9 = [](const DecimalNumber& n) {
    std::uint64_t f = n.frac;
    for (int d = n.frac_digits; d < 9; ++d) f *= 10;
    return f;
  };
  const auto negative = [](const DecimalNumber& n) { return n.negative && (n.int_part != 0 || n.frac != 0); };
  if (negative(a) != negative(b)) return negative(a);
  const auto smaller = [&](const DecimalNumber& x, const DecimalNumber& y) {  // in magnitude
    return x.int_part != y.int_part ? x.int_part < y.int_part : frac9(x) < frac9(y);
  };
  return negative(a) ? smaller(b, a) : smaller(a, b);
}

/// The value in `unit_ns` (ns per unit) as µs, rounded to nearest; false when
/// it does not fit.
bool to_us(const DecimalNumber& n, std::int64_t unit_ns, std::int64_t& t_us) noexcept;

}  // namespace evlife::io::detail
