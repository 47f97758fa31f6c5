// The one parser of numbers and of times with units, for every command-line
// flag, configuration value and render mode that takes one. No exceptions
// (algo builds without them): nullopt when the text is not a value; the
// caller names the flag or key in its message.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

namespace evlife {

/// The whole text as a finite decimal number ("1.5", "-3", "+2e3"), else nullopt.
std::optional<double> parse_decimal(std::string_view text) noexcept;

/// One sign at most, then decimal digits only ("12", "-3", "+7"): how an
/// integer flag is written; "2.0", "2e0" and "0x2" are no counts.
bool is_decimal_integer(std::string_view text) noexcept;

/// A time, >= 0, in microseconds: a number with a unit, "20us", "500ms",
/// "1.5s", or a bare number in seconds ("0.5"), rounded to the microsecond.
/// Else nullopt, also for a positive time that rounds to 0.
std::optional<std::int64_t> parse_time_us(std::string_view text) noexcept;

/// What parse_time_us accepts, for error messages.
inline constexpr std::string_view kTimeExamples =
    "a time such as 1.5s, 500ms, 20us or 0.5 (seconds), 0 or at least 1us (to the nearest us), at most 1e9s";

}  // namespace evlife
