// One configuration key: its dotted name, how to parse a value into the
// Config, its allowed range and how to print it. The table of all keys is
// the single description of the configuration schema.
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "evlife/config/config.h"

namespace evlife::config {

struct ConfigKey {
  std::string name;     ///< dotted, e.g. "estimator.window_size"
  std::string type;     ///< "integer", "number", "boolean", "string"
  std::string allowed;  ///< human text of the allowed range, e.g. "odd, [3, 15]"
  /// "integer": written in 0x hexadecimal too (a bit pattern: the seed); else decimal digits only.
  bool hex = false;
  std::string doc;      ///< one line, from the option's table
  /// Parses `text` (a YAML scalar) into the field; false when it is not a
  /// value of `type` (the range is checked separately by in_range).
  std::function<bool(Config&, std::string_view text)> parse;
  std::function<bool(const Config&)> in_range;
  /// The current value, exactly (round-trips through parse).
  std::function<std::string(const Config&)> format;
};

/// Every key of every section, in documentation order.
const std::vector<ConfigKey>& config_keys();

/// The key named `name`, or nullptr.
const ConfigKey* find_config_key(std::string_view name);

}  // namespace evlife::config
