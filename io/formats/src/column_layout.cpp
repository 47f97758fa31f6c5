#include "column_layout.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

namespace evlife::io::detail {

std::string lower_ascii(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string layout_text(const Layout& layout, int columns) {
  static constexpr const char* kRoleNames = "xytp";
  std::string text;
  for (int c = 0; c < columns; ++c) {
    if (c > 0) text += ',';
    char name = '_';
    for (int r = 0; r < 4; ++r)
      if (layout[static_cast<std::size_t>(r)] == c) name = kRoleNames[r];
    text += name;
  }
  return text;
}

std::int64_t unit_ns(std::string u) {
  u.erase(std::remove_if(u.begin(), u.end(), [](char c) { return c == ' ' || c == '_' || c == '(' || c == ')' || c == '[' || c == ']'; }), u.end());
  u = lower_ascii(std::move(u));  // NS, Seconds (an HDF5 units attribute)
  if (u == "s" || u == "sec" || u == "seconds" || u == "second") return 1'000'000'000;
  if (u == "ms" || u == "msec" || u == "milliseconds" || u == "millisecond") return 1'000'000;
  // µs with the micro sign or the Greek mu (both UTF-8).
  if (u == "us" || u == "usec" || u == "\xc2\xb5s" || u == "\xce\xbcs" || u == "microseconds" || u == "microsecond")
    return 1'000;
  if (u == "ns" || u == "nsec" || u == "nanoseconds" || u == "nanosecond") return 1;
  return 0;
}

int column_role(const std::string& name, std::int64_t& unit) {
  if (name == "x" || name == "xs") return kX;
  if (name == "y" || name == "ys") return kY;
  if (name == "p" || name == "ps" || name == "pol" || name == "polarity") return kP;
  for (const char* base : {"timestamps", "timestamp", "times", "time", "ts", "t"}) {
    const std::size_t n = std::strlen(base);
    if (name.compare(0, n, base) != 0) continue;
    const std::string rest = name.substr(n);
    if (rest.empty()) return kT;
    // A unit after a separator only: "tss" is no "ts" in seconds.
    const char sep = rest.front();
    if (sep != '_' && sep != ' ' && sep != '(' && sep != '[') continue;
    if (const std::int64_t u = unit_ns(rest)) {
      unit = u;
      return kT;
    }
  }
  return -1;
}

namespace {
// x,y,p,t (metavision_file_to_csv), x,y,t,p, t,x,y,p: kUnnamedLayouts' order.
constexpr std::array<Layout, 3> kCandidates = {{{0, 1, 3, 2}, {0, 1, 2, 3}, {1, 2, 0, 3}}};
}  // namespace

void ColumnTraits::add(std::size_t row, bool is_polarity, bool is_coordinate, bool is_fraction, bool below_previous) {
  const auto r = static_cast<std::int64_t>(row);
  fractional = fractional || is_fraction;
  if (polarity && !is_polarity) not_polarity_row = r;
  if (coordinate && !is_coordinate) not_coordinate_row = r;
  if (non_decreasing && below_previous) decreasing_row = r;
  polarity = polarity && is_polarity;
  coordinate = coordinate && is_coordinate;
  non_decreasing = non_decreasing && !below_previous;
}

std::string no_layout_reasons(const std::array<ColumnTraits, 4>& c,
                              const std::function<std::string(std::size_t)>& row_name,
                              const std::function<std::string(int)>& column_name,
                              const std::function<std::string(std::size_t, int)>& value) {
  std::string text;
  for (const Layout& l : kCandidates) {
    const auto at = [&](Role r) {
      const int column = l[static_cast<std::size_t>(r)];
      return std::pair{column, c[static_cast<std::size_t>(column)]};
    };
    const auto said = [&](std::int64_t row, int column, const std::string& what) {
      const auto r = static_cast<std::size_t>(row);
      return row_name(r) + "'s " + column_name(column) + " = " + value(r, column) + " " + what;
    };
    std::string why;
    if (const auto [column, t] = at(kP); !t.polarity) {
      why = said(t.not_polarity_row, column, "is not a polarity (1 ON, 0 or -1 OFF)");
    } else if (const auto [tc, tt] = at(kT); !tt.non_decreasing) {
      const auto r = static_cast<std::size_t>(tt.decreasing_row);
      why = said(tt.decreasing_row, tc, "goes back in time (" + row_name(r - 1) + "'s is " + value(r - 1, tc) + ")");
    } else {
      for (const Role role : {kX, kY}) {
        const auto [xc, xt] = at(role);
        if (xt.coordinate) continue;
        why = said(xt.not_coordinate_row, xc, std::string("is not ") + "xy"[role] + " (an integer 0..65535)");
        break;
      }
    }
    if (why.empty()) continue;  // it fits: only the others are ruled out
    text += (text.empty() ? "as " : "; as ") + layout_text(l, 4) + ", " + why;
  }
  return text;
}

LayoutChoice choose_layout(const std::array<ColumnTraits, 4>& c) {
  auto at = [&c](const Layout& l, Role r) -> const ColumnTraits& {
    return c[static_cast<std::size_t>(l[static_cast<std::size_t>(r)])];
  };
  std::vector<Layout> valid;
  for (const Layout& l : kCandidates) {
    if (at(l, kP).polarity && at(l, kT).non_decreasing && at(l, kX).coordinate && at(l, kY).coordinate)
      valid.push_back(l);
  }
  // A fractional time column settles it among the candidates.
  if (valid.size() > 1) {
    std::vector<Layout> with_frac;
    for (const Layout& l : valid)
      if (at(l, kT).fractional) with_frac.push_back(l);
    if (with_frac.size() == 1) valid = with_frac;
  }
  // Else a time column that moves, where the other candidate's does not.
  if (valid.size() > 1) {
    std::vector<Layout> moving;
    for (const Layout& l : valid)
      if (at(l, kT).moving) moving.push_back(l);
    if (moving.size() == 1) valid = moving;
  }
  LayoutChoice choice;
  choice.fitting = static_cast<int>(valid.size());
  if (choice.fitting == 1) choice.layout = valid.front();
  return choice;
}

bool integer_time_to_us(std::int64_t value, std::int64_t unit_ns, std::int64_t& t_us) noexcept {
  if (unit_ns >= 1000) {
    const std::int64_t factor = unit_ns / 1000;
    if (value > INT64_MAX / factor || value < INT64_MIN / factor) return false;
    t_us = value * factor;
  } else {  // ns: to nearest µs, halves away from zero
    t_us = value / 1000 + (value % 1000 >= 500 ? 1 : 0) - (value % 1000 <= -500 ? 1 : 0);
  }
  return true;
}

bool float_time_to_us(double value, std::int64_t unit_ns, std::int64_t& t_us) noexcept {
  const double us = value * (static_cast<double>(unit_ns) / 1000.0);
  if (!std::isfinite(us) || std::fabs(us) >= 9.2e18) return false;
  t_us = std::llround(us);
  return true;
}

}  // namespace evlife::io::detail
