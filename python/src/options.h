// Estimator options from Python keywords, through the same key table and
// ConfigBuilder as the command line's --config/--set: the keywords are the
// `estimator.` keys of config/evlife.yaml (without the prefix), checked
// against the same ranges, with the same messages.
#pragma once

#include <pybind11/pybind11.h>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "evlife/algo/event.h"
#include "evlife/config/config.h"
#include "evlife/io/event_reader.h"

namespace evlife::python {

namespace py = pybind11;

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

void bind_options(py::module_& m);

}  // namespace evlife::python
