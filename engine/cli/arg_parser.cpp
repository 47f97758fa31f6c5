#include "arg_parser.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "evlife/config/config_key.h"
#include "evlife/io/augmented_event_reader.h"
#include "evlife/io/stop.h"
#include "evlife/io/stream_copy_name.h"
#include "exit_code.h"

namespace evlife::cli {

std::optional<std::string> ParsedArgs::value(std::string_view name) const {
  const auto it = values_.find(name);
  if (it == values_.end() || it->second.empty()) return std::nullopt;
  return it->second.back();
}

std::vector<std::string> ParsedArgs::values(std::string_view name) const {
  const auto it = values_.find(name);
  return it == values_.end() ? std::vector<std::string>{} : it->second;
}

std::string ParsedArgs::typed_name(std::string_view name) const {
  const auto it = spelled_.find(name);
  if (it == spelled_.end() || !it->second.starts_with("--")) return std::string(name);  // -m: its long name
  return it->second.substr(2);
}

namespace {

// True when the comma-separated `list` holds `name`.
bool names_in(std::string_view list, std::string_view name) {
  while (!list.empty()) {
    const auto comma = std::min(list.find(','), list.size());
    if (list.substr(0, comma) == name) return true;
    list.remove_prefix(std::min(comma + 1, list.size()));
  }
  return false;
}

std::string unknown_option_message(std::string_view arg, std::span<const OptionSpec> options) {
  std::vector<std::string> names;
  for (const auto& o : options) {
    names.push_back("--" + std::string(o.name));
    for (std::string_view list = o.also; !list.empty();) {
      const auto comma = std::min(list.find(','), list.size());
      names.push_back("--" + std::string(list.substr(0, comma)));
      list.remove_prefix(std::min(comma + 1, list.size()));
    }
  }
  const std::vector<std::string_view> views(names.begin(), names.end());
  const std::string_view word = arg.substr(0, arg.find('='));
  std::string msg = "unknown option '" + std::string(arg) + "'";
  // A one-letter option is a few edits from any short long name: `info -q`
  // was asked "did you mean '--to'?". Its help lists the letters there are.
  if (arg.size() == 2 && arg[1] != '-') return msg;
  if (const std::string best = config::closest_name(word, views); !best.empty())
    msg += " (did you mean '" + best + "'?)";
  return msg;
}

}  // namespace

ParsedArgs parse_args(int argc, char** argv, std::span<const OptionSpec> options) {
  ParsedArgs out;
  bool options_done = false;
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (options_done || arg.size() < 2 || arg[0] != '-') {
      out.positional.emplace_back(arg);
      continue;
    }
    if (arg == "--") {
      options_done = true;
      continue;
    }
    const OptionSpec* spec = nullptr;
    std::optional<std::string> inline_value;
    if (arg[1] == '-') {
      std::string_view name = arg.substr(2);
      if (const auto eq = name.find('='); eq != std::string_view::npos) {
        inline_value = std::string(name.substr(eq + 1));
        name = name.substr(0, eq);
      }
      for (const auto& o : options) {
        if (o.name == name || names_in(o.also, name)) spec = &o;
      }
    } else {
      for (const auto& o : options) {
        if (o.alias != 0 && o.alias == arg[1]) spec = &o;
      }
      // -j2, -oout.bin: a short option's value attached, as getopt takes it.
      if (spec && arg.size() > 2) {
        if (!spec->takes_value) spec = nullptr;
        else inline_value = std::string(arg.substr(2));
      }
    }
    if (!spec) throw UsageError(unknown_option_message(arg, options));
    const std::string name(spec->name);
    std::string value;
    if (spec->takes_value) {
      if (inline_value) {
        value = *inline_value;
      } else if (i + 1 < argc) {
        value = argv[++i];
      } else {
        throw UsageError("option '" + std::string(arg) + "' needs a value");
      }
    } else if (inline_value) {
      throw UsageError("option '--" + name + "' takes no value");
    }
    if (name == kInputOptionSpec.name) {  // -i FILE: the positional INPUT
      out.positional.push_back(std::move(value));
      continue;
    }
    const std::string spelling(arg[1] == '-' ? arg.substr(0, arg.find('=')) : arg.substr(0, 2));  // "--at", "-o"
    auto& slot = out.values_[name];
    if (!slot.empty() && !spec->repeatable) {
      const std::string& first = out.spelled_[name];
      if (first != spelling) throw UsageError("'" + first + "' and '" + spelling + "' are the same option: give it once");
      throw UsageError("option '" + spelling + "' given more than once");
    }
    if (slot.empty()) out.spelled_[name] = spelling;
    slot.push_back(std::move(value));
  }
  return out;
}

std::int64_t parse_time_flag(std::string_view name, std::string_view text) {
  const auto us = parse_time_us(text);
  if (!us) {
    throw UsageError("--" + std::string(name) + " " + std::string(text) + ": expected " +
                     std::string(kTimeExamples));
  }
  return *us;
}

bool parse_common_args(const ParsedArgs& a, CommonArgs& out, bool crop) {
  out.config = load_command_config(a);  // (its ranges first: a bad value is named where it was set)
  // process, render, eval run no engine: an engine key set for them would be ignored.
  // (A --config file's engine: section is left alone: one file serves every command.)
  for (const std::string& v : a.values("set"))
    if (config::ConfigBuilder::key_of_assignment(v).starts_with("engine."))
      throw UsageError("--set " + v + ": engine settings are `evlife run`'s; this command runs no engine (one "
                       "thread, in order)");
  out.print_config = a.has("print-config");
  out.quiet = a.has("quiet");
  if (const auto s = a.value("sensor")) out.sensor = parse_sensor_size(*s);  // (--print-config shows it)
  if (out.print_config) return false;
  if (a.positional.empty()) throw UsageError("missing INPUT");
  if (a.positional.size() > 1) throw UsageError("more than one INPUT: '" + a.positional[1] + "'");
  out.input = a.positional.front();
  out.input_options = parse_input_options(a, crop);
  return true;
}

std::string config_options_help() {
  const std::string path = config::default_config_path();
  return "  --config FILE      YAML configuration; without it " +
         (path.empty() ? std::string("the built-in defaults") : path + " if present") +
         ".\n"
         "  --set KEY=VALUE    override one key, e.g. --set estimator.window_size=7.\n"
         "  --print-config     print the effective configuration (YAML) and exit.\n";
}

config::LoadedConfig load_command_config(const ParsedArgs& a) {
  const auto path = a.value("config");
  if (path && path->empty()) throw UsageError("--config needs a file name");
  return config::load_config(path.value_or(""), a.values("set"));
}

void print_config(const config::LoadedConfig& c, std::optional<SensorSize> sensor_flag) {
  // What the input decides stays a comment unless the user set it (--sensor
  // too: the run's size), so the output given back with --config configures
  // the same run.
  config::Config shown = c.config;
  std::string from = c.describe();
  if (sensor_flag) {
    shown.estimator.sensor = *sensor_flag;
    from += ", --sensor " + std::to_string(sensor_flag->width) + "x" + std::to_string(sensor_flag->height);
  }
  const bool user_set_them = sensor_flag || c.builder.user_origin_of_input_keys() != nullptr;
  const auto from_input = [&](std::string_view key) {
    return config::is_taken_from_the_input(key) && !user_set_them;
  };
  // One comment line whatever the path or --set held (a newline there ended it: the file did not load back).
  for (char& ch : from)
    if (ch == '\n' || ch == '\r') ch = ' ';
  std::fprintf(stdout, "# effective configuration (from %s)\n%s", from.c_str(), config::to_yaml(shown, from_input).c_str());
}

std::optional<SensorSize> user_sensor_size(std::optional<SensorSize> flag, const config::LoadedConfig& c) {
  if (flag) return flag;
  if (c.builder.user_origin_of_input_keys() != nullptr) return c.config.estimator.sensor;
  return std::nullopt;
}

void warn_sensor_flag_ignored(std::string_view command, SensorSize flag, std::string_view input, SensorSize used) {
  if (flag == used) return;
  std::fprintf(stderr, "evlife %.*s: warning: --sensor %dx%d ignored: %s states %dx%d\n",
               static_cast<int>(command.size()), command.data(), flag.width, flag.height,
               io::name_in_messages(std::string(input)).c_str(), used.width, used.height);
}

void warn_user_sensor_ignored(std::string_view command, std::optional<SensorSize> flag, const config::LoadedConfig& c,
                              std::string_view input, SensorSize used) {
  if (flag) return warn_sensor_flag_ignored(command, *flag, input, used);
  const config::KeyOrigin* origin = c.builder.user_origin_of_input_keys();
  const SensorSize set = c.config.estimator.sensor;
  if (origin == nullptr || set == used) return;
  std::fprintf(stderr, "evlife %.*s: warning: estimator.sensor %dx%d (%s) ignored: %s states %dx%d\n",
               static_cast<int>(command.size()), command.data(), set.width, set.height, origin->where.c_str(),
               io::name_in_messages(std::string(input)).c_str(), used.width, used.height);
}

int usage_exit(std::string_view command, std::string_view message) {
  const int c = static_cast<int>(command.size());
  std::fprintf(stderr, "evlife %.*s: %.*s\n(see evlife %.*s --help)\n", c, command.data(),
               static_cast<int>(message.size()), message.data(), c, command.data());
  return kExitUsage;
}

int open_fault_exit(std::string_view command, const std::string& input, const io::ReadError& e) {
  if (io::stop_requested()) {
    std::fprintf(stderr, "evlife %.*s: interrupted while opening %s: nothing processed\n",
                 static_cast<int>(command.size()), command.data(), io::name_in_messages(input).c_str());
    return kExitInterrupted;
  }
  if (dynamic_cast<const io::OptionNotTaken*>(&e) != nullptr) return usage_exit(command, e.what());
  std::fprintf(stderr, "evlife %.*s: input error: %s\n", static_cast<int>(command.size()), command.data(), e.what());
  return kExitInput;
}

int output_fault_exit(std::string_view command, std::string_view what, std::string_view suffix) {
  const bool stopped = io::stop_requested();
  std::fprintf(stderr, "evlife %.*s: %s: %.*s%.*s\n", static_cast<int>(command.size()), command.data(),
               stopped ? "interrupted" : "output error", static_cast<int>(what.size()), what.data(),
               static_cast<int>(suffix.size()), suffix.data());
  return stopped ? kExitInterrupted : kExitOutput;
}

std::string no_event_text(const std::string& input, const io::ReaderOptions& selection) {
  std::string text = "no event of " + io::name_in_messages(input);
  if (selection.polarity != io::PolarityFilter::both)
    text += selection.polarity == io::PolarityFilter::on ? " is ON (--polarity on)" : " is OFF (--polarity off)";
  if (selection.from_us || selection.to_us)
    text += " within --from/--to (times are seconds after its first event; `evlife info` gives its length)";
  return text;
}

void warn_empty_crop(std::string_view command, const std::string& input, const io::ReaderOptions& selection) {
  if (!selection.filters()) return;
  std::fprintf(stderr, "evlife %.*s: warning: %s\n", static_cast<int>(command.size()), command.data(),
               no_event_text(input, selection).c_str());
}

SensorSize parse_sensor_size(std::string_view text) {
  const auto x = text.find_first_of("xX");
  auto number = [&](std::string_view s, int& v) {
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    return !s.empty() && ec == std::errc() && ptr == s.data() + s.size() && v >= 1 && v <= kMaxSensorSide;
  };
  SensorSize size;
  if (x == std::string_view::npos || !number(text.substr(0, x), size.width) ||
      !number(text.substr(x + 1), size.height)) {
    throw UsageError("--sensor '" + std::string(text) + "': expected WIDTHxHEIGHT with each side in 1.." +
                     std::to_string(kMaxSensorSide) + ", e.g. 240x180");
  }
  return size;
}

std::vector<std::int64_t> parse_instants_us(std::string_view option, const std::string& text,
                                            std::string_view command) {
  if (text.empty()) throw UsageError("--" + std::string(option) + ": no time given");
  const std::size_t entries = static_cast<std::size_t>(std::count(text.begin(), text.end(), ',')) + 1;
  std::vector<std::int64_t> instants;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, comma - start);
    start = comma + 1;
    if (item.empty()) {  // (it was skipped: "0.5,,0.6" drew two frames without a word)
      throw UsageError("--" + std::string(option) + " " + text + ": entry " + std::to_string(instants.size() + 1) +
                       " of " + std::to_string(entries) + " is empty");
    }
    instants.push_back(parse_time_flag(option, item));
  }
  std::sort(instants.begin(), instants.end());
  instants.erase(std::unique(instants.begin(), instants.end()), instants.end());
  if (instants.size() < entries)  // (they were merged unsaid: 4 instants asked, 2 frames drawn)
    std::fprintf(stderr, "evlife %.*s: note: --%.*s: %zu of its %zu instants repeat a microsecond already given (as "
                         "written or rounded to the us): %zu drawn, each once\n",
                 static_cast<int>(command.size()), command.data(), static_cast<int>(option.size()), option.data(),
                 entries - instants.size(), entries, instants.size());
  return instants;
}

io::ReaderOptions parse_input_options(const ParsedArgs& a, bool crop) {
  io::ReaderOptions options;
  if (const auto topic = a.value("topic")) {
    if (topic->empty()) throw UsageError("--topic: empty topic name");
    options.topic = *topic;
  }
  if (const auto unit = a.value("time-unit")) {
    if (*unit != "s" && *unit != "ms" && *unit != "us" && *unit != "ns")
      throw UsageError("--time-unit " + *unit + ": expected s, ms, us or ns");
    options.time_unit = *unit;
  }
  if (const auto pol = a.value("polarity")) {
    const std::optional<io::PolarityFilter> filter = io::parse_polarity_filter(*pol);
    if (!filter) throw UsageError("--polarity " + *pol + ": expected on, off or both");
    options.polarity = *filter;
  }
  if (!crop) return options;
  for (const char* name : {"from", "to"}) {
    const auto v = a.value(name);
    if (!v) continue;
    const std::int64_t us = parse_time_flag(name, *v);
    (std::string_view(name) == "from" ? options.from_us : options.to_us) = us;
  }
  if (options.crop_is_empty())
    throw UsageError(options.from_us ? "--to must be after --from" : "--to must be after --from (0 without it)");
  return options;
}

std::string selecting_flags(const io::ReaderOptions& options) {
  std::string flags;
  const auto add = [&](const char* flag) { flags += (flags.empty() ? "" : ", ") + std::string(flag); };
  if (options.polarity != io::PolarityFilter::both) add("--polarity");
  if (options.from_us || options.to_us) add("--from/--to");
  if (!options.time_unit.empty()) add("--time-unit");
  if (!options.topic.empty()) add("--topic");
  return flags;
}

bool is_evlife_output(const std::string& input) {
  try {
    return io::open_if_augmented(input) != nullptr;
  } catch (const io::ReadError&) {  // a .bin that does not read: the command's reader says why
    return true;
  }
}

namespace {

bool sizes_the_sensor(std::string_view key) { return key.starts_with("estimator.sensor."); }

}  // namespace

void refuse_selection_of_augmented(const io::ReaderOptions& options, const std::string& input) {
  const std::string flags = selecting_flags(options);
  if (flags.empty() || !is_evlife_output(input)) return;
  throw UsageError(flags + ": nothing to select in " + input +
                   ", evlife's output (read whole: its lifetimes came from the whole recording); "
                   "select when processing the recording");
}

void refuse_estimator_settings_for_augmented(std::string_view command, const CommonArgs& args,
                                             const std::vector<std::string>& set_values) {
  std::string sets, from_files;
  for (const std::string& v : set_values)
    if (const std::string key = config::ConfigBuilder::key_of_assignment(v);
        key.starts_with("estimator.") && !sizes_the_sensor(key))
      sets += (sets.empty() ? "--set " : ", --set ") + v;
  // A --config file's keys, but only values that differ from the defaults:
  // `--print-config`'s file given back restates all of them, changing nothing.
  std::optional<config::Config> standard;  // built when a file sets an estimator key
  for (const config::ConfigKey& k : config::config_keys()) {
    const config::KeyOrigin* o = args.config.builder.origin(k.name);
    if (o == nullptr || !o->by_user || o->where.starts_with("--set") || !k.name.starts_with("estimator.") ||
        sizes_the_sensor(k.name))
      continue;
    if (!standard) {
      config::ConfigBuilder defaults;
      defaults.load_default_file_if_present();
      standard = defaults.build();
    }
    if (k.format(args.config.config) != k.format(*standard)) from_files += (from_files.empty() ? "" : ", ") + k.name;
  }
  if ((sets.empty() && from_files.empty()) || !is_evlife_output(args.input)) return;
  const std::string why = "nothing to estimate in " + args.input +
                          ", evlife's output (its lifetimes were estimated when the recording was processed)";
  if (!sets.empty()) throw UsageError(sets + ": " + why + "; set it when processing the recording");
  std::fprintf(stderr, "evlife %.*s: warning: %s of --config ignored: %s\n", static_cast<int>(command.size()),
               command.data(), from_files.c_str(), why.c_str());
}

bool has_extension(const std::string& path, std::initializer_list<std::string_view> extensions) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return std::find(extensions.begin(), extensions.end(), ext) != extensions.end();
}

}  // namespace evlife::cli
