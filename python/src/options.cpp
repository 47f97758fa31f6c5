#include "options.h"

#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "bindings.h"
#include "errors.h"
#include "evlife/config/config_key.h"

namespace evlife::python {
namespace {

bool is_estimator_key(const config::ConfigKey& k) {
  return k.name.compare(0, kEstimatorPrefix.size(), kEstimatorPrefix) == 0 &&
         k.name.rfind("estimator.sensor.", 0) != 0;  // the sensor has its own argument
}

// The Python value as the YAML scalar the key's parser takes. Types are
// strict (a bool is no number, a float no integer); a str passes as written,
// as on the command line.
std::string scalar_text(const config::ConfigKey& key, const std::string& keyword,
                        const py::handle& value) {
  if (py::isinstance<py::str>(value)) return value.cast<std::string>();
  const bool is_bool = is_a_bool(value);
  if (key.type == "boolean") {
    if (!is_bool) throw py::type_error(keyword + ": expected True or False");
    return py::cast<bool>(py::bool_(py::reinterpret_borrow<py::object>(value))) ? "true" : "false";
  }
  if (is_bool) {
    throw py::type_error(keyword + ": expected " + (key.type == "integer" ? "an " : "a ") + key.type + ", got a bool");
  }
  if (key.type == "integer") {
    if (!py::hasattr(value, "__index__")) {
      throw py::type_error(keyword + ": expected an integer, got " +
                           std::string(py::str(py::type::of(value).attr("__name__"))));
    }
    return py::str(py::int_(value.attr("__index__")())).cast<std::string>();
  }
  if (key.type == "number") {
    if (py::hasattr(value, "__index__")) {
      return py::str(py::int_(value.attr("__index__")())).cast<std::string>();
    }
    if (!py::hasattr(value, "__float__")) {
      throw py::type_error(keyword + ": expected a number, got " +
                           std::string(py::str(py::type::of(value).attr("__name__"))));
    }
    // repr(float) is the shortest text that reads back exactly, as the table's format.
    return py::repr(py::float_(py::reinterpret_borrow<py::object>(value))).cast<std::string>();
  }
  return py::str(value).cast<std::string>();
}

// The key's current value as a Python object of its type.
py::object key_value(const config::ConfigKey& key, const config::Config& c) {
  const std::string text = key.format(c);
  if (key.type == "boolean") return py::bool_(text == "true");
  if (key.type == "integer") return py::module_::import("builtins").attr("int")(text);
  if (key.type == "number") return py::module_::import("builtins").attr("float")(text);  // stod fails on subnormals
  return py::str(text);
}

// repr(value), cut short: an array's would fill the screen.
std::string short_repr(const py::handle& value) {
  std::string text;
  try {
    text = py::repr(value).cast<std::string>();
  } catch (const py::error_already_set&) {
    text = "?";
  }
  return text.size() <= 80 ? text : text.substr(0, 77) + "...";
}

}  // namespace

bool is_a_bool(const py::handle& value) {
  return py::isinstance<py::bool_>(value) || py::isinstance(value, py::module_::import("numpy").attr("bool_"));
}

void raise_argument_type_error(const std::string& where, const char* name, const std::string& expected,
                               const py::handle& value) {
  throw py::type_error(where + "(): " + name + " must be " + expected + ", got " +
                       py::str(py::type::of(value).attr("__name__")).cast<std::string>() + " " + short_repr(value));
}

void raise_argument_range_error(const std::string& where, const char* name, long long min, unsigned long long max,
                                const py::handle& value) {
  const py::int_ number(py::reinterpret_borrow<py::object>(value).attr("__index__")());
  const bool below = number < py::int_(min);
  throw py::value_error(where + "(): " + name + " must be " +
                        (below ? "at least " + std::to_string(min) : "at most " + std::to_string(max)) + ", got " +
                        short_repr(number));
}

std::string path_argument(const std::string& where, const char* name, const py::handle& value) {
  try {
    return path_from_python(value);
  } catch (const py::type_error& e) {
    throw py::type_error(where + "(): " + name + ": " + e.what());
  }
}

double float_argument(const std::string& where, const char* name, const py::handle& value, const char* unit) {
  const std::string expected = std::string("a number") + (*unit ? std::string(" (") + unit + ")" : "");
  if (is_a_bool(value)) raise_argument_type_error(where, name, expected, value);  // True is no 1.0 s
  try {
    return py::cast<double>(value);
  } catch (const py::cast_error&) {
    raise_argument_type_error(where, name, expected, value);
  }
}

std::optional<double> optional_float_argument(const std::string& where, const char* name, const py::handle& value,
                                              const char* unit) {
  if (value.is_none()) return std::nullopt;
  return float_argument(where, name, value, unit);
}

std::string str_argument(const std::string& where, const char* name, const py::handle& value) {
  try {
    return py::cast<std::string>(value);
  } catch (const py::cast_error&) {
    raise_argument_type_error(where, name, "a str", value);
  }
}

std::optional<std::string> optional_str_argument(const std::string& where, const char* name,
                                                 const py::handle& value) {
  if (value.is_none()) return std::nullopt;
  return str_argument(where, name, value);
}

bool bool_argument(const std::string& where, const char* name, const py::handle& value) {
  if (!is_a_bool(value)) raise_argument_type_error(where, name, "True or False", value);
  return py::cast<bool>(py::bool_(py::reinterpret_borrow<py::object>(value)));
}

std::string misspelled_keyword(std::string_view keyword, const std::vector<std::string_view>& keywords,
                               const std::vector<std::string_view>& others) {
  std::vector<std::string_view> candidates(keywords.begin(), keywords.end());
  candidates.insert(candidates.end(), others.begin(), others.end());
  const std::string best = config::closest_name(keyword, candidates);
  return std::find(keywords.begin(), keywords.end(), best) != keywords.end() ? best : std::string();
}

std::string unexpected_keyword(const std::string& where, std::string_view keyword) {
  return where + "() got an unexpected keyword argument '" + std::string(keyword) + "'";
}

void refuse_keywords(const std::string& where, const py::dict& kwargs, const std::vector<std::string_view>& keywords) {
  for (const auto& [k, v] : kwargs) {
    const std::string keyword = py::str(k).cast<std::string>();
    const std::string meant = misspelled_keyword(keyword, keywords);
    throw py::type_error(unexpected_keyword(where, keyword) + (meant.empty() ? "" : " (did you mean '" + meant + "'?)"));
  }
}

ReaderArguments reader_arguments(const std::string& where, const py::handle& from_s, const py::handle& to_s,
                                 const py::handle& topic, const py::handle& time_unit, const py::handle& polarity) {
  ReaderArguments a;  // in the order of the signature: the first wrong one is named
  a.from_s = optional_float_argument(where, "from_s", from_s, "seconds");
  a.to_s = optional_float_argument(where, "to_s", to_s, "seconds");
  a.topic = optional_str_argument(where, "topic", topic);
  a.time_unit = optional_str_argument(where, "time_unit", time_unit);
  a.polarity = optional_str_argument(where, "polarity", polarity);
  return a;
}

io::ReaderOptions reader_options(const std::string& where, std::optional<SensorSize> sensor, const py::handle& from_s,
                                 const py::handle& to_s, const py::handle& topic, const py::handle& time_unit,
                                 const py::handle& polarity) {
  const ReaderArguments a = reader_arguments(where, from_s, to_s, topic, time_unit, polarity);
  return reader_options(sensor, a.from_s, a.to_s, a.topic, a.time_unit, a.polarity);
}

io::ReaderOptions reader_options(std::optional<SensorSize> sensor, std::optional<double> from_s,
                                 std::optional<double> to_s, const std::optional<std::string>& topic,
                                 const std::optional<std::string>& time_unit,
                                 const std::optional<std::string>& polarity) {
  io::ReaderOptions options(sensor, true);
  if (polarity) {
    const std::optional<io::PolarityFilter> filter = io::parse_polarity_filter(*polarity);
    if (!filter) throw py::value_error("polarity: expected 'on', 'off' or 'both', got '" + *polarity + "'");
    options.polarity = *filter;
  }
  if (topic) {
    if (topic->empty()) throw py::value_error("topic: empty topic name");
    options.topic = *topic;
  }
  if (time_unit) {
    if (*time_unit != "s" && *time_unit != "ms" && *time_unit != "us" && *time_unit != "ns")
      throw py::value_error("time_unit: expected 's', 'ms', 'us' or 'ns', got '" + *time_unit + "'");
    options.time_unit = *time_unit;
  }
  const auto to_us = [](const char* name, double seconds) {
    char given[32];
    std::snprintf(given, sizeof given, "%g", seconds);  // (std::to_string wrote 1e300's 301 digits)
    if (!(seconds >= 0.0 && seconds <= 1e9))  // also NaN
      throw py::value_error(std::string(name) + " must be seconds after the first event, in [0, 1e9], got " + given);
    const auto us = static_cast<std::int64_t>(std::llround(seconds * 1e6));
    if (us == 0 && seconds > 0.0)  // as the CLI's --from/--to: not "to_s must be after from_s"
      throw py::value_error(std::string(name) + " = " + given + " s rounds to 0 us: 0 or at least 1e-6 (1 us)");
    return us;
  };
  if (from_s) options.from_us = to_us("from_s", *from_s);
  if (to_s) options.to_us = to_us("to_s", *to_s);
  if (options.crop_is_empty())
    throw py::value_error(from_s ? "to_s must be after from_s" : "to_s must be after from_s (0 without it)");
  return options;
}

void warn_empty_crop(const char* function, const std::string& path, const io::ReaderOptions& crop,
                     std::uint64_t events, int stacklevel) {
  if (events > 0 || !crop.filters()) return;
  std::string text = std::string(function) + ": no event of " + path;
  if (crop.polarity != io::PolarityFilter::both)
    text += crop.polarity == io::PolarityFilter::on ? " is ON (polarity='on')" : " is OFF (polarity='off')";
  if (crop.from_us || crop.to_us)
    text += " within from_s/to_s (seconds after its first event; evlife.scan gives its t_first and t_last)";
  warn_at_callers_line(text, stacklevel);
}

std::string skipped_records_warning(const std::string& function, const std::string& path, std::uint64_t count,
                                    const std::vector<io::SkippedKindCount>& kinds) {
  if (count == 0) return {};
  const std::string by_kind = io::skipped_kinds_text(kinds);
  return function + ": " + path + ": " + std::to_string(count) + " non-event records of the format skipped" +
         (by_kind.empty() ? "" : " (" + by_kind + ")") +
         ", as the CLI's summary counts them; evlife.open(path).skipped_record_kinds has them too";
}

void warn_skipped_records(const char* function, const std::string& path, std::uint64_t count,
                          const std::vector<io::SkippedKindCount>& kinds, int stacklevel) {
  if (const std::string text = skipped_records_warning(function, path, count, kinds); !text.empty())
    warn_at_callers_line(text, stacklevel);
}

std::optional<SensorSize> optional_sensor_from_python(const py::object& sensor) {
  if (sensor.is_none()) return std::nullopt;
  return sensor_from_python(sensor);
}

SensorSize sensor_from_python(const py::object& sensor) {
  if (!py::isinstance<py::sequence>(sensor) || py::len(sensor) != 2 ||
      py::isinstance<py::str>(sensor)) {
    throw py::type_error("sensor: expected (width, height), e.g. (240, 180)");
  }
  const auto seq = sensor.cast<py::sequence>();
  SensorSize s;
  try {
    s.width = py::int_(seq[0].attr("__index__")()).cast<int>();
    s.height = py::int_(seq[1].attr("__index__")()).cast<int>();
  } catch (const py::error_already_set&) {
    throw py::type_error("sensor: expected two integers (width, height)");
  } catch (const py::cast_error&) {
    throw py::value_error("sensor: width and height must be 1.." + std::to_string(kMaxSensorSide));
  }
  if (!s.within_camera_limits()) {  // a file no reader accepts, an estimator that cannot be made
    throw py::value_error("sensor: width and height must be 1.." + std::to_string(kMaxSensorSide) + ", got (" +
                          std::to_string(s.width) + ", " + std::to_string(s.height) + ")");
  }
  return s;
}

namespace {

// config= as --config: the documented default file when None, else a path
// as evlife.read takes one (str(b'...') named a file "b'...'").
void load_config_argument(config::ConfigBuilder& b, const py::object& config_path) {
  if (config_path.is_none()) {
    b.load_default_file_if_present();
    return;
  }
  std::string path;
  try {
    path = path_from_python(config_path);
  } catch (const py::type_error& e) {
    throw py::type_error(std::string("config: ") + e.what());
  }
  b.load_file(path);
}

}  // namespace

ResolvedOptions resolve_options(const std::string& where, const py::object& sensor,
                                const py::object& config_path, const py::dict& options,
                                const std::vector<std::string_view>& own_keywords) {
  config::ConfigBuilder b;
  load_config_argument(b, config_path);
  for (const auto& [k, v] : options) {
    const std::string keyword = py::str(k).cast<std::string>();
    const std::string key = std::string(kEstimatorPrefix) + keyword;
    const config::ConfigKey* ck = config::find_config_key(key);
    if (ck == nullptr || !is_estimator_key(*ck)) {
      std::string message = unexpected_keyword(where, keyword);
      // A misspelling of the function's own keywords (one_thred=, form_s=) is
      // said so, not as an unknown estimator key (with the estimator's keys).
      std::vector<std::string> names;
      for (const auto& c : config::config_keys())
        if (is_estimator_key(c)) names.push_back(c.name.substr(kEstimatorPrefix.size()));
      const std::string best = misspelled_keyword(keyword, own_keywords, {names.begin(), names.end()});
      if (!best.empty()) throw py::type_error(message + " (did you mean '" + best + "'?)");
      // The configuration's own message (closest key, the keys of the section).
      try {
        b.set(key, "0", where);
      } catch (const config::ConfigError& e) {
        message += ": " + std::string(e.what());
      }
      if (ck != nullptr) message += " (give the sensor as sensor=(width, height))";
      throw py::type_error(message);
    }
    const std::string text = scalar_text(*ck, keyword, v);
    b.set(key, text, where + "(" + keyword + "=" + text + ")");
  }
  ResolvedOptions r;
  if (!sensor.is_none()) {
    const SensorSize s = sensor_from_python(sensor);
    const std::string origin = where + "(sensor=(" + std::to_string(s.width) + ", " +
                               std::to_string(s.height) + "))";
    b.set("estimator.sensor.width", std::to_string(s.width), origin);
    b.set("estimator.sensor.height", std::to_string(s.height), origin);
  }
  r.config = b.build();
  if (b.user_origin_of_input_keys() != nullptr) r.sensor = r.config.estimator.sensor;
  return r;
}

void bind_options(py::module_& m) {
  m.def(
      "_refuse_keywords",
      [](const std::string& where, const py::dict& kwargs, const std::vector<std::string>& keywords) {
        refuse_keywords(where, kwargs, {keywords.begin(), keywords.end()});
      },
      py::arg("where"), py::arg("kwargs"), py::arg("keywords"),
      "Internal: TypeError for the first of kwargs, as the C++ functions say it (did you mean one of keywords?).");
  m.def(
      "_misspelled_keyword",
      [](const std::string& keyword, const std::vector<std::string>& keywords, const std::vector<std::string>& others) {
        return misspelled_keyword(keyword, {keywords.begin(), keywords.end()}, {others.begin(), others.end()});
      },
      py::arg("keyword"), py::arg("keywords"), py::arg("others"),
      "Internal: the one of keywords that keyword misspells (the nearest of keywords and others), or ''.");
  m.def(
      "estimator_options",
      [](py::object config_path, const py::kwargs& kw) {
        refuse_keywords("evlife.estimator_options", kw, {"config"});
        config::ConfigBuilder b;
        load_config_argument(b, config_path);
        const config::Config c = b.build();
        py::dict out;
        for (const auto& k : config::config_keys()) {
          if (!is_estimator_key(k)) continue;
          py::dict d;
          d["type"] = k.type;
          d["allowed"] = k.allowed;
          d["default"] = key_value(k, c);
          out[py::str(k.name.substr(kEstimatorPrefix.size()))] = d;
        }
        return out;
      },
      py::arg("config") = py::none(),
      "The estimator's keyword options: {name: {'type', 'allowed', 'default'}}.\n\n"
      "The same table as the `estimator:` section of config/evlife.yaml and the\n"
      "command line's --set estimator.NAME=VALUE; defaults as `evlife process`\n"
      "uses them (the documented default file when present, or `config`).");
}

py::dict options_dict(const config::Config& c) {
  py::dict out;
  for (const auto& k : config::config_keys()) {
    if (is_estimator_key(k)) out[py::str(k.name.substr(kEstimatorPrefix.size()))] = key_value(k, c);
  }
  return out;
}

}  // namespace evlife::python
