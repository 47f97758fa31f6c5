// Estimator options from Python keywords, through the same key table and
// ConfigBuilder as the command line's --config/--set: the keywords are the
// `estimator.` keys of config/evlife.yaml (without the prefix), checked
// against the same ranges, with the same messages.
#pragma once

#include <pybind11/pybind11.h>

#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "evlife/algo/event.h"
#include "evlife/config/config.h"
#include "evlife/io/event_reader.h"

namespace evlife::python {

namespace py = pybind11;

/// Any object: an argument pybind11 hands over as it is, converted by the
/// function itself so that a wrong one is named ("evlife.read(): from_s must
/// be a number (seconds), got str '0.5'"), where pybind11's "incompatible
/// function arguments" named none and printed every argument (a whole array).
/// Each type shows in the signature (help()) as the type it stands for.
inline bool is_any_object(PyObject*) { return true; }
#define EVLIFE_ARGUMENT_TYPE(Name)                          \
  class Name : public py::object {                           \
   public:                                                   \
    PYBIND11_OBJECT_DEFAULT(Name, py::object, is_any_object) \
  };
EVLIFE_ARGUMENT_TYPE(PathArgument)           // os.PathLike
EVLIFE_ARGUMENT_TYPE(FloatArgument)          // float
EVLIFE_ARGUMENT_TYPE(IntArgument)            // int
EVLIFE_ARGUMENT_TYPE(StrArgument)            // str
EVLIFE_ARGUMENT_TYPE(OptionalFloatArgument)  // Optional[float]
EVLIFE_ARGUMENT_TYPE(OptionalIntArgument)    // Optional[int]
EVLIFE_ARGUMENT_TYPE(OptionalStrArgument)    // Optional[str]
EVLIFE_ARGUMENT_TYPE(BoolArgument)           // bool
#undef EVLIFE_ARGUMENT_TYPE

/// The conversions of those arguments, as pybind11 made them (the same values
/// pass), else TypeError "WHERE(): NAME must be ..., got TYPE REPR" (the repr
/// cut short), or ValueError for a whole number below `min` / beyond the type.
/// `unit` ("seconds", "events"; "" for none) is said in parentheses.
std::string path_argument(const std::string& where, const char* name, const py::handle& value);
double float_argument(const std::string& where, const char* name, const py::handle& value, const char* unit);
std::optional<double> optional_float_argument(const std::string& where, const char* name, const py::handle& value,
                                              const char* unit);
std::string str_argument(const std::string& where, const char* name, const py::handle& value);
std::optional<std::string> optional_str_argument(const std::string& where, const char* name, const py::handle& value);
/// True or False (Python's or NumPy's bool): no truth value of another type
/// ("no" was a pybind11 error printing the whole input, None and 1 passed).
bool bool_argument(const std::string& where, const char* name, const py::handle& value);
/// TypeError "WHERE(): NAME must be EXPECTED, got TYPE REPR".
[[noreturn]] void raise_argument_type_error(const std::string& where, const char* name, const std::string& expected,
                                            const py::handle& value);
/// ValueError "WHERE(): NAME must be at least MIN, got VALUE" (or beyond MAX).
[[noreturn]] void raise_argument_range_error(const std::string& where, const char* name, long long min,
                                             unsigned long long max, const py::handle& value);
/// A Python bool, or NumPy's (np.bool_, e.g. a mask's element, which has no
/// __index__): no number where a number is asked (True passed as 1).
bool is_a_bool(const py::handle& value);
template <class Int>
Int int_argument(const std::string& where, const char* name, const py::handle& value, const char* unit,
                 long long min) {
  const std::string expected = std::string("a whole number") + (*unit ? std::string(" (") + unit + ")" : "");
  if (is_a_bool(value)) raise_argument_type_error(where, name, expected, value);
  try {
    return py::cast<Int>(value);
  } catch (const py::cast_error&) {
  }
  if (!PyFloat_Check(value.ptr()) && py::hasattr(value, "__index__"))  // a whole number the type cannot hold
    raise_argument_range_error(where, name, min, static_cast<unsigned long long>(std::numeric_limits<Int>::max()),
                               value);
  raise_argument_type_error(where, name, expected, value);
}
template <class Int>
std::optional<Int> optional_int_argument(const std::string& where, const char* name, const py::handle& value,
                                         const char* unit, long long min) {
  if (value.is_none()) return std::nullopt;
  return int_argument<Int>(where, name, value, unit, min);
}

/// The one of `keywords` that `keyword` misspells, or "": the nearest name
/// (config::closest_name, the rule of the CLI's options and keys) among
/// `keywords` and `others` when it is one of `keywords` (others: a function's
/// estimator options, which have their own message).
std::string misspelled_keyword(std::string_view keyword, const std::vector<std::string_view>& keywords,
                               const std::vector<std::string_view>& others = {});

/// "WHERE() got an unexpected keyword argument 'KEYWORD'", as Python says it.
std::string unexpected_keyword(const std::string& where, std::string_view keyword);

/// TypeError for the first keyword of `kwargs` (those pybind11 matched to no
/// parameter): unexpected_keyword, with " (did you mean 'NAME'?)" for the one
/// of `keywords` (the function's) it misspells.
void refuse_keywords(const std::string& where, const py::dict& kwargs, const std::vector<std::string_view>& keywords);

/// The prefix of the keys that are estimator keywords.
inline constexpr std::string_view kEstimatorPrefix = "estimator.";

struct ResolvedOptions {
  config::Config config;
  /// The sensor given by the caller (sensor= keyword) or by the user's
  /// configuration file; nullopt when neither did.
  std::optional<SensorSize> sensor;
};

/// Starts as `evlife process` does (the documented default file when there is
/// no `config_path`, else that file), then applies `options` and `sensor`
/// ((width, height) or None) and validates. `where` names the caller in
/// messages, e.g. "evlife.LifetimeEstimator". Unknown keywords raise
/// TypeError, bad values ValueError (the CLI's text); one nearest to a name
/// of `own_keywords` (the caller's other keywords: one_thread, from_s, ...)
/// is said to be its misspelling.
ResolvedOptions resolve_options(const std::string& where, const py::object& sensor,
                                const py::object& config_path, const py::dict& options,
                                const std::vector<std::string_view>& own_keywords = {});

/// The estimator keywords' current values in `c`, {name: value}.
py::dict options_dict(const config::Config& c);

/// (width, height) -> SensorSize; TypeError/ValueError otherwise.
SensorSize sensor_from_python(const py::object& sensor);
/// The same, None -> nullopt.
/// A RuntimeWarning "FUNCTION: no event of PATH within from_s/to_s ..." when
/// `events` is 0 and `crop` selects a time range or a polarity: an empty result says why
/// (the CLI's warning). Needs the GIL.
void warn_empty_crop(const char* function, const std::string& path, const io::ReaderOptions& crop,
                     std::uint64_t events, int stacklevel = 2);

/// A RuntimeWarning "FUNCTION: PATH: N non-event records of the format
/// skipped (kind N, ...)" when `count` > 0: triggers, IMU samples, frames,
/// words of no event a whole-file call read past (the CLI's summary line).
void warn_skipped_records(const char* function, const std::string& path, std::uint64_t count,
                          const std::vector<io::SkippedKindCount>& kinds, int stacklevel = 2);
/// Its text ("" when `count` is 0), for a caller that warns elsewhere (evlife.batch).
std::string skipped_records_warning(const std::string& function, const std::string& path, std::uint64_t count,
                                    const std::vector<io::SkippedKindCount>& kinds);

std::optional<SensorSize> optional_sensor_from_python(const py::object& sensor);

/// What evlife.read, open, process and process_file read: `sensor`, the
/// CLI's --from / --to as from_s / to_s, seconds after the first event of the
/// file, --topic (a ROS bag's event topic, an HDF5 file's camera, an .npz
/// array), --time-unit (CSV/text and NumPy files: s, ms, us or ns) and
/// --polarity ("on", "off", "both").
/// ValueError for a negative time, to_s not after from_s or an empty topic
/// (as the CLI).
io::ReaderOptions reader_options(std::optional<SensorSize> sensor, std::optional<double> from_s,
                                 std::optional<double> to_s, const std::optional<std::string>& topic = std::nullopt,
                                 const std::optional<std::string>& time_unit = std::nullopt,
                                 const std::optional<std::string>& polarity = std::nullopt);

/// from_s, to_s, topic, time_unit, polarity as given in Python (None, a
/// number, a str), converted by the *_argument functions: a wrong type is a
/// TypeError naming `where` and the argument.
struct ReaderArguments {
  std::optional<double> from_s, to_s;
  std::optional<std::string> topic, time_unit, polarity;
};
ReaderArguments reader_arguments(const std::string& where, const py::handle& from_s, const py::handle& to_s,
                                 const py::handle& topic, const py::handle& time_unit, const py::handle& polarity);
/// reader_options of reader_arguments.
io::ReaderOptions reader_options(const std::string& where, std::optional<SensorSize> sensor, const py::handle& from_s,
                                 const py::handle& to_s, const py::handle& topic, const py::handle& time_unit,
                                 const py::handle& polarity);

void bind_options(py::module_& m);

}  // namespace evlife::python

// The signature help() shows for each argument type: the type it stands for.
namespace pybind11::detail {
#define EVLIFE_ARGUMENT_TYPE_NAME(Name, shown) \
  template <>                                  \
  struct handle_type_name<evlife::python::Name> { static constexpr auto name = const_name(shown); };
EVLIFE_ARGUMENT_TYPE_NAME(PathArgument, "os.PathLike")
EVLIFE_ARGUMENT_TYPE_NAME(FloatArgument, "float")
EVLIFE_ARGUMENT_TYPE_NAME(IntArgument, "int")
EVLIFE_ARGUMENT_TYPE_NAME(StrArgument, "str")
EVLIFE_ARGUMENT_TYPE_NAME(OptionalFloatArgument, "Optional[float]")
EVLIFE_ARGUMENT_TYPE_NAME(OptionalIntArgument, "Optional[int]")
EVLIFE_ARGUMENT_TYPE_NAME(OptionalStrArgument, "Optional[str]")
EVLIFE_ARGUMENT_TYPE_NAME(BoolArgument, "bool")
#undef EVLIFE_ARGUMENT_TYPE_NAME
}  // namespace pybind11::detail
