// Minimal command-line parsing shared by the subcommands: long options with
// or without a value (`--opt v`, `--opt=v`), one-letter aliases (`-o v`),
// repeatable options, positionals, `--` to end options. Errors throw
// UsageError with a message naming the argument.
#pragma once

#include <algorithm>
#include <cstdio>
#include <map>
#include <type_traits>
#include <optional>
#include <span>
#include <stdexcept>
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include "evlife/algo/event.h"
#include "evlife/algo/option_info.h"
#include "evlife/algo/parse_text.h"
#include "evlife/config/config.h"
#include "evlife/io/event_reader.h"

namespace evlife::cli {

class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct OptionSpec {
  std::string_view name;     ///< long name without dashes, e.g. "output"
  char alias = 0;            ///< e.g. 'o' for -o; 0 = none
  bool takes_value = true;   ///< false: a flag
  bool repeatable = false;   ///< e.g. --set
  /// Other long names accepted for the same option (older or other commands'
  /// spellings), comma-separated, e.g. "render-fps"; values land under `name`.
  std::string_view also = {};
};

/// `-i FILE` / `--input FILE`: the same as the positional INPUT (parse_args
/// puts its value among the positionals, in command-line order).
inline constexpr OptionSpec kInputOptionSpec{"input", 'i', true, true};
/// The configuration, on every command that uses it (load_command_config).
inline constexpr OptionSpec kConfigOptionSpec{"config", 0, true, false};
inline constexpr OptionSpec kSetOptionSpec{"set", 0, true, true};
inline constexpr OptionSpec kPrintConfigOptionSpec{"print-config", 0, false, false};
/// --help's lines of --config, --set and --print-config (with the default
/// file's path, config::default_config_path()).
std::string config_options_help();

class ParsedArgs {
 public:
  std::vector<std::string> positional;

  bool has(std::string_view name) const { return values_.find(name) != values_.end(); }
  /// The value of a single-valued option, if given.
  std::optional<std::string> value(std::string_view name) const;
  /// Every value of a repeatable option, in command-line order.
  std::vector<std::string> values(std::string_view name) const;
  /// The long name option `name` was given under, for its errors: an alias
  /// of OptionSpec::also as typed (eval's --at for --frame-at), else `name`.
  std::string typed_name(std::string_view name) const;

 private:
  friend ParsedArgs parse_args(int, char**, std::span<const OptionSpec>);
  std::map<std::string, std::vector<std::string>, std::less<>> values_;
  std::map<std::string, std::string, std::less<>> spelled_;  ///< option -> how it was first written: "--at", "-o"
};

/// Parses argv[1..argc) (argv[0] is the subcommand name). Throws UsageError;
/// an unknown option's message suggests the nearest known one.
ParsedArgs parse_args(int argc, char** argv, std::span<const OptionSpec> options);

/// The one number parser of the flags: the whole text a decimal number in
/// [lo, hi] (and whole for integer T), else UsageError naming --`name`.
template <typename T>
T parse_number(std::string_view name, std::string_view text, T lo, T hi);

/// The one time parser of the flags (evlife/algo/parse_text.h): "1.5s",
/// "500ms", "20us" or a bare number of seconds, >= 0, in microseconds.
std::int64_t parse_time_flag(std::string_view name, std::string_view text);

/// A flag's value read by a parser that throws std::invalid_argument naming
/// the value (render::parse_view_mode, parse_color_mode): `parse()`'s result,
/// else UsageError "--`name` WHAT", e.g. "--mode window must be longer than 0
/// in 'window:0'" (the one rule of render's and run's --mode and --color).
template <typename Parse>
auto parse_flag_with(std::string_view name, Parse&& parse) -> decltype(parse()) {
  try {
    return parse();
  } catch (const std::invalid_argument& e) {
    throw UsageError("--" + std::string(name) + " " + e.what());
  }
}

/// A flag of an option table (evlife/algo/option_info.h): the flag's value,
/// checked against the table's range, into `field`. Floating fields whose
/// key ends in "_s" take a time with units (stats-period 500ms).
template <typename T>
void parse_table_flag(const OptionInfo& info, std::string_view text, T& field);

/// What every command that reads one recording with the estimator's
/// configuration takes (process, render, eval): INPUT (or -i), --sensor, the
/// input selection, --config/--set/--print-config, -q.
struct CommonArgs {
  std::string input;
  std::optional<SensorSize> sensor;
  io::ReaderOptions input_options;
  config::LoadedConfig config;
  bool print_config = false;
  bool quiet = false;
};

/// Fills `out`'s CommonArgs part; with --print-config it stops after the
/// configuration (no INPUT needed) and returns false. `crop`: --from/--to
/// select the events read (see parse_input_options).
bool parse_common_args(const ParsedArgs& a, CommonArgs& out, bool crop = true);

/// The command's configuration from --config / --set (config::load_config:
/// the one loading path). Throws config::ConfigError.
config::LoadedConfig load_command_config(const ParsedArgs& a);

/// --print-config: the effective configuration as YAML, on stdout, with
/// --sensor (`sensor_flag`) as the estimator's sensor.
void print_config(const config::LoadedConfig& c, std::optional<SensorSize> sensor_flag = std::nullopt);

/// The sensor size the user gave, the second step of every command's sensor
/// rule (the size the format states first, a scan of the data last):
/// --sensor (`flag`), else estimator.sensor where --config or --set sets it.
std::optional<SensorSize> user_sensor_size(std::optional<SensorSize> flag, const config::LoadedConfig& c);

/// "COMMAND: warning: --sensor WxH ignored: INPUT states WxH" when the size
/// used is not the flag's (the format states its own).
void warn_sensor_flag_ignored(std::string_view command, SensorSize flag, std::string_view input, SensorSize used);

/// The same for user_sensor_size(): the flag's, else estimator.sensor's where
/// --config or --set set it ("estimator.sensor WxH (WHERE) ignored: ...";
/// that one was dropped without a word).
void warn_user_sensor_ignored(std::string_view command, std::optional<SensorSize> flag, const config::LoadedConfig& c,
                              std::string_view input, SensorSize used);

/// A usage error: "evlife COMMAND: MESSAGE", where to read more, exit 2.
int usage_exit(std::string_view command, std::string_view message);

/// An input error met while COMMAND opened INPUT: "interrupted while opening
/// INPUT: nothing processed" and exit 130 where a stop signal came (io/stop.h:
/// a bag's decompression ends so); an option the input's format does not take
/// (io::OptionNotTaken) is a usage error, exit 2; else "input error: WHAT", exit 3.
int open_fault_exit(std::string_view command, const std::string& input, const io::ReadError& e);

/// An output error of COMMAND (`what`: the error's text, which names the
/// file), opening or writing: "interrupted: WHAT" and exit 130 where a stop
/// signal came (a FIFO's writer gives up waiting for its reader so,
/// io/stop.h); else "output error: WHAT", exit 4; `suffix` follows WHAT.
int output_fault_exit(std::string_view command, std::string_view what, std::string_view suffix = {});

/// "no event of INPUT", and where --from/--to selected the events, how to
/// read them (a warning's text: process and eval say it alike).
std::string no_event_text(const std::string& input, const io::ReaderOptions& selection);
/// "evlife COMMAND: warning: no event of INPUT within --from/--to ..." on
/// stderr when `selection` crops (a run that read to its end and found no
/// event there: not silent).
void warn_empty_crop(std::string_view command, const std::string& input, const io::ReaderOptions& selection);

/// "  --flag  doc [range]" lines of an option table's entries that have a flag.
template <typename ForEach>
std::string table_flags_help(ForEach for_each);

/// "WIDTHxHEIGHT", e.g. "240x180", each 1..4096. Throws UsageError.
SensorSize parse_sensor_size(std::string_view text);

/// True when `path` ends in one of `extensions` (".txt", ...), case aside, as
/// the writers choose their format.
/// The flags in `options` that select a recording's events ("--polarity,
/// --from/--to"), "" for none. evlife's own output (an augmented .bin/.csv)
/// is read whole: the commands refuse them there (exit 2) instead of
/// ignoring them.
std::string selecting_flags(const io::ReaderOptions& options);

/// True for an augmented file of `evlife process` (and a .bin that does not
/// read: the command's reader says why).
bool is_evlife_output(const std::string& input);

/// The usage error of selecting_flags() for `input`, when there are any.
void refuse_selection_of_augmented(const io::ReaderOptions& options, const std::string& input);

/// render and eval of evlife's output (its lifetimes estimated already):
/// `--set estimator.*` is refused (a usage error), the estimator keys a
/// --config file sets are warned of (a file often configures every command).
/// Both were ignored without a word. (estimator.sensor.* still sizes a file
/// that states none.)
void refuse_estimator_settings_for_augmented(std::string_view command, const CommonArgs& args,
                                             const std::vector<std::string>& set_values);

bool has_extension(const std::string& path, std::initializer_list<std::string_view> extensions);

/// "T1,T2,..." (seconds, or with a unit: 250ms, 40us) -> microseconds,
/// sorted, without repeats; `option` names the flag in errors. Throws UsageError,
/// also for an empty entry ("0.5,,0.6"). `command`: repeats (the same
/// microsecond, as written or rounded) are said on stderr, each drawn once.
std::vector<std::int64_t> parse_instants_us(std::string_view option, const std::string& text,
                                            std::string_view command);

/// The input selection shared by every command that reads events: --topic
/// (ROS bags). Add kInputOptionSpecs' entries to the command's option table
/// and kInputOptionsHelp to its help. The sensor stays unset.
/// `crop`: also --from/--to (render has its own, for the frames it draws).
io::ReaderOptions parse_input_options(const ParsedArgs& a, bool crop = true);
inline constexpr OptionSpec kTopicOptionSpec{"topic", 0, true, false};
inline constexpr OptionSpec kTimeUnitOptionSpec{"time-unit", 0, true, false};
inline constexpr OptionSpec kPolarityOptionSpec{"polarity", 0, true, false};
inline constexpr OptionSpec kFromOptionSpec{"from", 0, true, false};
inline constexpr OptionSpec kToOptionSpec{"to", 0, true, false};
inline constexpr std::string_view kInputOptionsHelp =
    "  INPUT -            stdin (also a named pipe, or <(unzip -p x.zip events.txt)):\n"
    "                     copied into $TMPDIR first and removed at the end; the\n"
    "                     format is then told by its content (.dat, .bag, .mcap: a file).\n"
    "  --topic NAME       ROS bags: the event topic to read (needed when the bag has\n"
    "                     several; the error lists them). HDF5: the camera to read,\n"
    "                     MVSEC davis/right/events, M3ED prophesee/right (default:\n"
    "                     the left), or any group of x, y, t, p columns. NumPy .npz:\n"
    "                     the array of events to read (when it holds several).\n"
    "  --time-unit U      CSV/text, NumPy and HDF5 input: unit of the time column, s|ms|us|ns\n"
    "                     (default: the header's or field name's, t_ns, datetime64's or\n"
    "                     an HDF5 units attribute's; else s if the times are fractions\n"
    "                     or floats, 0.25, else us).\n"
    "  --polarity on|off|both  read only ON or only OFF events (default both).\n";
inline constexpr std::string_view kCropOptionsHelp =
    "  --from T, --to T   read only the events from T to T (exclusive) after the first\n"
    "                     event of the file; seconds or with a unit (250ms, 40us, 2s).\n"
    "                     HDF5 input starts at --from by a search on t, without\n"
    "                     decoding the events before it.\n";

// The number in a flag's text: a finite decimal, for an integer flag in
// decimal digits only, as its configuration key (a count of 2.0, 2e0 or 0x2
// is a slip); else nullopt.
template <typename T>
std::optional<double> flag_number(std::string_view text) {
  if (std::is_integral_v<T> && !is_decimal_integer(text)) return std::nullopt;
  return parse_decimal(text);
}

template <typename T>
T parse_number(std::string_view name, std::string_view text, T lo, T hi) {
  const auto v = flag_number<T>(text);
  bool ok = v && *v >= static_cast<double>(lo) && *v <= static_cast<double>(hi);
  if constexpr (std::is_integral_v<T>) ok = ok && *v == static_cast<double>(static_cast<T>(*v));
  if (!ok) {
    auto num = [](T x) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%g", static_cast<double>(x));
      return std::string(buf);
    };
    const std::string lo_text = num(lo), hi_text = num(hi);
    throw UsageError("--" + std::string(name) + " " + std::string(text) + ": expected " +
                     (std::is_integral_v<T> ? "a whole number" : "a number") + " in [" + lo_text +
                     ", " + hi_text + "]");
  }
  return static_cast<T>(*v);
}

template <typename T>
void parse_table_flag(const OptionInfo& info, std::string_view text, T& field) {
  double v = 0.0;
  bool number = true;
  if (std::is_floating_point_v<T> && info.key.ends_with("_s")) {
    v = static_cast<double>(parse_time_flag(info.flag, text)) * 1e-6;
  } else if (const auto parsed = flag_number<T>(text)) {
    v = *parsed;
  } else {
    number = false;  // "nan", "0x10", "1e400", a count of "2.0": said with the flag's own range
  }
  const bool whole = std::is_floating_point_v<T> || v == std::floor(v);
  if (!number || !whole || !info.contains(v)) {
    const char* kind = std::is_integral_v<T> ? "a whole number in " : "a number in ";
    throw UsageError("--" + std::string(info.flag) + " " + std::string(text) + ": expected " +
                     (number && whole ? "" : kind) + info.range_text());
  }
  field = static_cast<T>(v);
}

template <typename ForEach>
std::string table_flags_help(ForEach for_each) {
  std::string out;
  for_each([&](const OptionInfo& info, auto) {
    if (info.flag.empty()) return;
    std::string head = "  --" + std::string(info.flag) + " " +
                       (info.key.ends_with("_s") ? "T" : "N");
    head.resize(std::max<std::size_t>(head.size() + 1, 23), ' ');
    std::string line = head + std::string(info.doc) + ";";
    std::string range = " ";  // appended, not `" " + string&&`: GCC 12's false -Wrestrict (PR 105329)
    range += info.range_text();
    range += '.';
    if (line.size() + range.size() > 80) {  // the range on a line of its own
      out += line + "\n";
      line = std::string(23, ' ') + range.substr(1);
    } else {
      line += range;
    }
    out += line + "\n";
  });
  return out;
}

}  // namespace evlife::cli
