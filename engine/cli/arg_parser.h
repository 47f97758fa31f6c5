// Minimal command-line parsing shared by the subcommands: long options with
// or without a value (`--opt v`, `--opt=v`), one-letter aliases (`-o v`),
// repeatable options, positionals, `--` to end options. Errors throw
// UsageError with a message naming the argument.
#pragma once

#include <map>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "evlife/algo/event.h"
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
};

class ParsedArgs {
 public:
  std::vector<std::string> positional;

  bool has(std::string_view name) const { return values_.find(name) != values_.end(); }
  /// The value of a single-valued option, if given.
  std::optional<std::string> value(std::string_view name) const;
  /// Every value of a repeatable option, in command-line order.
  std::vector<std::string> values(std::string_view name) const;

 private:
  friend ParsedArgs parse_args(int, char**, std::span<const OptionSpec>);
  std::map<std::string, std::vector<std::string>, std::less<>> values_;
};

/// Parses argv[1..argc) (argv[0] is the subcommand name). Throws UsageError.
ParsedArgs parse_args(int argc, char** argv, std::span<const OptionSpec> options);

/// "WIDTHxHEIGHT", e.g. "240x180", each 1..4096. Throws UsageError.
SensorSize parse_sensor_size(std::string_view text);

/// "T1,T2,..." (seconds, or with a unit: 250ms, 40us) -> microseconds,
/// sorted, without repeats; `option` names the flag in errors. Throws UsageError.
std::vector<std::int64_t> parse_instants_us(std::string_view option, const std::string& text);

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
    "  --topic NAME       ROS bags: the event topic to read (needed when the bag has\n"
    "                     several; the error lists them).\n"
    "  --time-unit U      CSV/text input: unit of the time column, s|ms|us|ns (default:\n"
    "                     the header's, else s if the times have a decimal point, else us).\n"
    "  --polarity on|off|both  read only ON or only OFF events (default both).\n";
inline constexpr std::string_view kCropOptionsHelp =
    "  --from T, --to T   read only the events from T to T (exclusive) after the first\n"
    "                     event of the file; seconds or with a unit (250ms, 40us, 2s).\n";

}  // namespace evlife::cli
