// Private: which of four columns holds x, y, t and p, for readers of tables
// without a fixed layout (CSV/text, NumPy .npy): by name (a header line, a
// structured array's fields) or, unnamed, by what the first rows hold.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

namespace evlife::io::detail {

enum Role { kX = 0, kY = 1, kT = 2, kP = 3 };
/// Column index of x, y, t, p.
using Layout = std::array<int, 4>;

/// `s` with ASCII letters in lower case (names are matched so).
std::string lower_ascii(std::string s);

/// "x,y,t,p"-style text of a layout over `columns` columns ('_' for the others).
std::string layout_text(const Layout& layout, int columns);

/// ns per unit named `u` (s, ms, us, µs, ns, seconds, nanosecond...; any
/// case; blanks, '_' and brackets ignored), 0 if unknown.
std::int64_t unit_ns(std::string u);

/// A time of `unit_ns` ns per unit as µs, rounded to nearest (ns: halves
/// away from zero); false when it does not fit int64 µs (NaN, ±inf too).
bool integer_time_to_us(std::int64_t value, std::int64_t unit_ns, std::int64_t& t_us) noexcept;
bool float_time_to_us(double value, std::int64_t unit_ns, std::int64_t& t_us) noexcept;

/// The role of a lower-case column name: x|xs, y|ys, p|ps|pol|polarity,
/// t|ts|time|times|timestamp|timestamps, the time optionally with a unit
/// after a separator (t_us, timestamp(ns), t [s]; then `unit` is set); -1 for
/// any other name. A table naming one role twice is refused by its reader.
int column_role(const std::string& name, std::int64_t& unit);

/// column_role's names, for messages (one text with the rule above).
inline constexpr const char* kColumnNames =
    "x|xs, y|ys, t|ts|time|times|timestamp|timestamps (a unit after '_', a blank or in brackets: t_us, "
    "timestamp(ns)) and p|ps|pol|polarity";
/// The unnamed layouts choose_layout() tells apart, for messages.
inline constexpr const char* kUnnamedLayouts = "x,y,p,t (metavision_file_to_csv), x,y,t,p or t,x,y,p";

/// What the first rows of one unnamed column hold.
struct ColumnTraits {
  bool polarity = true;        ///< integers in [-1, 1] only
  bool coordinate = true;      ///< integers in [0, 65535] only
  bool non_decreasing = true;  ///< never decreases from row to row
  bool fractional = false;     ///< some value written or stored as a fraction
  bool moving = false;         ///< its first and last rows differ in their integer part
  // The first sampled row that broke polarity, coordinate, non_decreasing (-1: none): for messages.
  std::int64_t not_polarity_row = -1;
  std::int64_t not_coordinate_row = -1;
  std::int64_t decreasing_row = -1;

  /// Sampled row `row`'s value, in order from row 0: `is_polarity` (an
  /// integer in [-1, 1]), `is_coordinate`, `is_fraction`, and `below_previous`
  /// (row > 0 and smaller than the row before).
  void add(std::size_t row, bool is_polarity, bool is_coordinate, bool is_fraction, bool below_previous);
};

struct LayoutChoice {
  int fitting = 0;  ///< how many layouts fit: 1 is a choice, 0 or more are not
  Layout layout{};  ///< when fitting == 1
};

/// The unnamed layouts read, x,y,p,t (metavision_file_to_csv), x,y,t,p and
/// t,x,y,p: the one the traits allow (p polarity, t non-decreasing, x and y
/// coordinates); among several, the only one whose t is fractional, else the
/// only one whose t moves; else none.
LayoutChoice choose_layout(const std::array<ColumnTraits, 4>& columns);

/// Why no unnamed layout fits, layout by layout, with the row and value that
/// rule each out: "as x,y,p,t, record 1's column 2 = 10 is not a polarity (...);
/// as x,y,t,p, ...". `row_name(r)`: "record 1", "line 2"; `column_name(c)`:
/// "column 2" (0-based, as NumPy counts), "field 3" (1-based, as a line's);
/// `value(r, column)`: the value as stored or written.
std::string no_layout_reasons(const std::array<ColumnTraits, 4>& columns,
                              const std::function<std::string(std::size_t)>& row_name,
                              const std::function<std::string(int)>& column_name,
                              const std::function<std::string(std::size_t, int)>& value);

}  // namespace evlife::io::detail
