#include "decimal_number.h"

#include <algorithm>

namespace evlife::io::detail {
namespace {

constexpr int kMaxExponent = 40;  // beyond it no coordinate or time is meant

// With an exponent: the digits placed after the exponent is known.
bool parse_with_exponent(const char* p, const char* end, DecimalNumber& n) noexcept {
  n = DecimalNumber{};
  if (p < end && (*p == '-' || *p == '+')) n.negative = *p++ == '-';
  const char* mantissa = p;
  int int_digits = 0;
  int all_digits = 0;
  while (p < end && is_decimal_digit(*p)) ++p, ++int_digits;
  all_digits = int_digits;
  if (p < end && *p == '.') {
    n.has_point = true;
    ++p;
    while (p < end && is_decimal_digit(*p)) ++p, ++all_digits;
  }
  if (all_digits == 0) return false;
  const char* mantissa_end = p;
  int exponent = 0;
  if (p < end && (*p == 'e' || *p == 'E')) {
    n.has_exponent = true;
    ++p;
    bool exponent_negative = false;
    if (p < end && (*p == '-' || *p == '+')) exponent_negative = *p++ == '-';
    if (p == end || !is_decimal_digit(*p)) return false;
    while (p < end && is_decimal_digit(*p)) {
      exponent = exponent * 10 + (*p++ - '0');
      if (exponent > kMaxExponent) return false;
    }
    if (exponent_negative) exponent = -exponent;
  }
  if (p != end) return false;

  // Digit i (0-based, the point skipped) lies before the point when i < point;
  // else it is fraction digit i - point (0 = tenths).
  const int point = int_digits + exponent;
  int i = 0;
  for (const char* q = mantissa; q < mantissa_end; ++q) {
    if (*q == '.') continue;
    const auto d = static_cast<std::uint64_t>(*q - '0');
    if (i < point) {
      if (n.int_part > (UINT64_MAX - 9) / 10) return false;
      n.int_part = n.int_part * 10 + d;
    } else {
      const int position = i - point;
      if (d != 0) n.integral = false;
      if (position < 9) {
        std::uint64_t scaled = d;
        for (int k = position; k < 8; ++k) scaled *= 10;
        n.frac += scaled;  // as if 9 digits were written
      } else if (position == 9) {
        n.round_up = d >= 5;
      }
    }
    ++i;
  }
  for (; i < point; ++i) {  // an exponent beyond the digits: trailing zeros
    if (n.int_part > UINT64_MAX / 10) return false;
    n.int_part *= 10;
  }
  if (!n.integral || all_digits > int_digits) n.frac_digits = 9;
  return true;
}

}  // namespace

bool parse_decimal(const char* p, const char* end, DecimalNumber& n) noexcept {
  // One pass for what text files mostly hold (no exponent); else the general parse.
  const char* begin = p;
  n = DecimalNumber{};
  if (p < end && (*p == '-' || *p == '+')) n.negative = *p++ == '-';
  const char* digits = p;
  while (p < end && is_decimal_digit(*p)) {
    if (n.int_part > (UINT64_MAX - 9) / 10) return false;  // 19 digits hold epoch ns (ROS exports)
    n.int_part = n.int_part * 10 + static_cast<std::uint64_t>(*p++ - '0');
  }
  bool any = p != digits;
  if (p < end && *p == '.') {
    n.has_point = true;
    ++p;
    while (p < end && is_decimal_digit(*p)) {
      if (*p != '0') n.integral = false;
      if (n.frac_digits < 9) {
        n.frac = n.frac * 10 + static_cast<std::uint64_t>(*p - '0');
        ++n.frac_digits;
      } else if (n.frac_digits == 9) {
        n.round_up = *p >= '5';
        ++n.frac_digits;
      }
      any = true;
      ++p;
    }
  }
  if (any && p < end && (*p == 'e' || *p == 'E')) return parse_with_exponent(begin, end, n);
  return any && p == end;
}

namespace {
__extension__ using Wide = __int128;  // GCC and Clang on 64-bit targets (x86-64, aarch64)
}  // namespace

bool to_us(const DecimalNumber& n, std::int64_t unit_ns, std::int64_t& t_us) noexcept {
  // value_ns = int_part * unit_ns + frac * unit_ns / 10^digits (digits <= 9),
  // in 128 bits: 19 digits of seconds are < 2^64 * 10^9 ns, far inside, so
  // every time the events can hold (|t| <= 2^62 us, event.h) reads, in any
  // unit (in 64-bit ns the limit was 146 years of us: what `convert` wrote
  // of a later time did not read back).
  const int digits = std::min(n.frac_digits, 9);
  const auto unit = static_cast<Wide>(unit_ns);
  Wide ns = static_cast<Wide>(n.int_part) * unit;
  std::int64_t pow10 = 1;
  for (int i = 0; i < digits; ++i) pow10 *= 10;
  ns += (static_cast<Wide>(n.frac) * unit + (n.round_up ? unit / 2 : 0)) / pow10;
  const Wide us = (ns + 500) / 1000;
  if (us > static_cast<Wide>(INT64_MAX)) return false;
  t_us = n.negative ? -static_cast<std::int64_t>(us) : static_cast<std::int64_t>(us);
  return true;
}

}  // namespace evlife::io::detail
