// Builders of ConfigKey for the usual field types (internal to config/).
#pragma once

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "evlife/algo/option_info.h"
#include "evlife/config/config_key.h"

namespace evlife::config::detail {

bool parse_bool(std::string_view text, bool& out);
bool parse_double(std::string_view text, double& out);
// Integers: one sign at most, then decimal digits only ("0x2", "2.0", "2e0",
// "2_0" are none, though YAML 1.2's core schema reads 0x2 and Python's int()
// 2_0); 0x hexadecimal where `hex`.
bool parse_int64(std::string_view text, long long& out);
bool parse_uint64(std::string_view text, unsigned long long& out, bool hex);
/// The text is a whole number as those read it, of any size: what a value
/// beyond its field's type is.
bool is_integer_text(std::string_view text, bool hex);
std::string format_double(double v);  // shortest text that parses back exactly

/// The key of one option of a table (evlife/algo/option_info.h): its name is
/// `section.info.key`, its type follows the field's, its range is the
/// table's. `field` is a generic lambda returning a reference to the field in
/// a Config (called with Config& and const Config&).
template <typename Field>
ConfigKey table_key(std::string_view section, const OptionInfo& info, Field field);

/// An unsigned option whose range is the whole 64-bit type is a bit pattern
/// (the seed): written in hex too, and every value parsed is in its range (a
/// double cannot tell the type's top values apart).
constexpr bool is_bit_pattern(const OptionInfo& info) { return info.hi >= 1.8e19 && info.lo <= 0; }

template <typename T, typename Field>
ConfigKey number_key(std::string name, Field field, const OptionInfo& info) {
  ConfigKey k;
  k.name = std::move(name);
  k.allowed = info.range_text();
  k.doc = std::string(info.doc);
  if constexpr (std::is_floating_point_v<T>) {
    k.type = "number";
    k.parse = [field](Config& c, std::string_view text) {
      double v = 0;
      if (!parse_double(text, v)) return false;
      field(c) = static_cast<T>(v);
      return true;
    };
    k.format = [field](const Config& c) { return format_double(field(c)); };
  } else if constexpr (std::is_unsigned_v<T>) {
    k.type = "integer";
    k.hex = is_bit_pattern(info);
    k.parse = [field, hex = k.hex](Config& c, std::string_view text) {
      unsigned long long v = 0;
      if (!parse_uint64(text, v, hex) || v > static_cast<unsigned long long>(std::numeric_limits<T>::max()))
        return false;
      field(c) = static_cast<T>(v);
      return true;
    };
    k.format = [field](const Config& c) { return std::to_string(field(c)); };
  } else {
    k.type = "integer";
    k.parse = [field](Config& c, std::string_view text) {
      long long v = 0;
      if (!parse_int64(text, v) || v < static_cast<long long>(std::numeric_limits<T>::min()) ||
          v > static_cast<long long>(std::numeric_limits<T>::max())) {
        return false;
      }
      field(c) = static_cast<T>(v);
      return true;
    };
    k.format = [field](const Config& c) { return std::to_string(field(c)); };
  }
  k.in_range = [field, info](const Config& c) {
    if (std::is_unsigned_v<T> && is_bit_pattern(info)) return true;
    return info.contains(static_cast<double>(field(c)));
  };
  return k;
}

template <typename Field>
ConfigKey bool_key(std::string name, Field field) {
  ConfigKey k;
  k.name = std::move(name);
  k.type = "boolean";
  k.allowed = "true or false";
  k.parse = [field](Config& c, std::string_view text) {
    bool v = false;
    if (!parse_bool(text, v)) return false;
    field(c) = v;
    return true;
  };
  k.in_range = [](const Config&) { return true; };
  k.format = [field](const Config& c) { return std::string(field(c) ? "true" : "false"); };
  return k;
}

/// A string restricted to `choices` (empty = any string).
template <typename Field>
ConfigKey string_key(std::string name, Field field, const std::vector<std::string>& choices = {}) {
  ConfigKey k;
  k.name = std::move(name);
  k.type = "string";
  if (choices.empty()) {
    k.allowed = "any text";
  } else {
    for (const auto& c : choices) k.allowed += (k.allowed.empty() ? "one of: " : ", ") + c;
  }
  k.parse = [field](Config& c, std::string_view text) {
    field(c) = std::string(text);
    return true;
  };
  k.in_range = [field, choices](const Config& c) {
    if (choices.empty()) return true;
    for (const auto& s : choices) {
      if (s == field(c)) return true;
    }
    return false;
  };
  k.format = [field](const Config& c) { return std::string(field(c)); };
  return k;
}

template <typename Field>
ConfigKey table_key(std::string_view section, const OptionInfo& info, Field field) {
  std::string name = std::string(section) + "." + std::string(info.key);
  using T = std::remove_cvref_t<decltype(field(std::declval<Config&>()))>;
  if constexpr (std::is_same_v<T, bool>) {
    ConfigKey k = bool_key(std::move(name), field);
    k.doc = std::string(info.doc);
    return k;
  } else {
    return number_key<T>(std::move(name), field, info);
  }
}

/// A field of a table's section in a Config, for table_key(): the tables'
/// accessors are captureless generic lambdas, called here through function
/// pointers, so that the keys' parse/format code is one instantiation per
/// field type and section, not one per field (40 instantiations of it made
/// the static analyzer take over a minute on estimator_keys.cpp).
template <typename T, typename Section>
struct SectionField {
  Section Config::* section;
  T& (*get)(Section&);
  const T& (*get_const)(const Section&);
  T& operator()(Config& c) const { return get(c.*section); }
  const T& operator()(const Config& c) const { return get_const(c.*section); }
};

/// Appends a key per entry of an option table: `for_each(f)` calls
/// f(info, accessor) per field (for_each_lifetime_option,
/// for_each_engine_option), `member` is the section in Config.
template <typename Section, typename ForEach>
void add_table_keys(std::vector<ConfigKey>& keys, std::string_view section, Section Config::* member,
                    ForEach for_each) {
  for_each([&](const OptionInfo& info, auto field) {
    using Field = decltype(field);  // captureless: default-constructible (C++20)
    using T = std::remove_cvref_t<decltype(field(std::declval<Section&>()))>;
    keys.push_back(table_key(section, info,
                             SectionField<T, Section>{member, [](Section& s) -> T& { return Field{}(s); },
                                                      [](const Section& s) -> const T& { return Field{}(s); }}));
  });
}

// One function per section appends its keys (listed in config_key.cpp).
void add_estimator_keys(std::vector<ConfigKey>& keys);
void add_engine_keys(std::vector<ConfigKey>& keys);

}  // namespace evlife::config::detail
