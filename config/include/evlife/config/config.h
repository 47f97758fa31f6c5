// The evlife configuration: one plain struct per YAML section, parsed and
// validated once (at start-up, never on a per-event path).
//
//   ConfigBuilder b;                       // the struct defaults
//   b.load_file("my.yaml");                // keys in the file replace defaults
//   b.set("estimator.window_size=7");      // --set overrides, dotted keys
//   Config c = b.build();                  // validates every key once
//
// Adding a section (e.g. `render:`): add a member to Config (a plain struct
// with defaults — its header must not pull in the owning library's
// dependencies; config/ links only evlife::algo), describe its keys in
// src/<section>_keys.cpp (see estimator_keys.cpp: one line per key with its
// range), call that function in src/config_key.cpp, and document the keys in
// config/evlife.yaml (test_config fails until the file lists every key with
// the struct's default value).
#pragma once

#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "evlife/algo/lifetime_options.h"
#include "evlife/engine/engine_options.h"  // a plain struct: config links no engine code

namespace evlife::config {

struct Config {
  LifetimeOptions estimator;  ///< YAML section `estimator:`, 1:1 with LifetimeOptions
  /// YAML section `engine:` (`evlife run`), 1:1 with the table next to
  /// EngineOptions (and its policy); `engine.lifetime` is not read from it:
  /// the estimator's options are `estimator` (the CLI copies them in).
  engine::EngineOptions engine;
};

/// Any configuration problem: the message names the key, where it was set
/// (file:line or --set) and what is allowed.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Where a key's value came from.
struct KeyOrigin {
  std::string where;       ///< "path:line" or "--set"
  bool by_user = false;    ///< false for the default file
};

class ConfigBuilder {
 public:
  /// Starts from the struct defaults (the compiled-in defaults).
  ConfigBuilder();

  /// Reads a YAML file; its keys replace the current values. Throws
  /// ConfigError for a missing file, a syntax error, an unknown key or a
  /// value of the wrong type (naming file, line and key). Ranges are checked
  /// by build(). `by_user` = false marks the shipped default file.
  void load_file(const std::string& path, bool by_user = true);

  /// Loads EVLIFE_DEFAULT_CONFIG when that file exists (the documented
  /// defaults in the source tree) and returns its path; returns "" when it
  /// is gone (installed binary): then the struct defaults stand.
  std::string load_default_file_if_present();

  /// Applies one "dotted.key=value" override (the value as in YAML).
  void set(std::string_view assignment);
  /// The key of such an override as set() reads it (blanks around it dropped).
  static std::string key_of_assignment(std::string_view assignment);

  /// Same for one key and its value, `where` naming the origin in messages
  /// (e.g. a Python keyword argument). Throws ConfigError as set() does.
  void set(std::string_view key, std::string_view value, const std::string& where);

  /// Validates every key once; throws ConfigError naming the first bad key,
  /// its value, where it was set and the allowed range.
  Config build() const;

  /// Non-null when the key was given by a file or --set.
  const KeyOrigin* origin(std::string_view key) const;

  /// Where the user set a key the input decides otherwise (is_taken_from_the_input:
  /// the sensor's width or height, which bind together), or null: the default
  /// file's values there do not count.
  const KeyOrigin* user_origin_of_input_keys() const;

 private:
  void assign(std::string_view key, std::string_view value, const std::string& where,
              bool by_user);

  Config config_;
  std::map<std::string, KeyOrigin, std::less<>> origins_;
};

/// Path of the documented default file: after use_installed_configuration(),
/// an installed tool's own copy (share/evlife/evlife.yaml beside its bin/)
/// when there is one; else the source tree's.
std::string default_config_path();

/// The evlife tool calls this at start: it looks for its own installed
/// configuration beside its executable. A library in another program (the
/// Python module in python3) does not: it would look beside that program.
void use_installed_configuration();

/// A configuration as every command loads it, with where it came from.
struct LoadedConfig {
  Config config;
  ConfigBuilder builder;               ///< origins of the keys (origin())
  std::string source;                  ///< the file read, or "built-in defaults"
  std::vector<std::string> overrides;  ///< the --set assignments, in order

  /// "FILE, --set a=b, ..." for summaries.
  std::string describe() const;
};

/// The one loading path of every command: `path` when given, else the shipped
/// default file when present (else the struct defaults), then the overrides
/// in order; validated. Throws ConfigError.
LoadedConfig load_config(const std::string& path, const std::vector<std::string>& overrides = {});

/// The candidate nearest to `name` (at most 3 edits away), else "": the
/// "did you mean" of configuration keys, commands and flags.
std::string closest_name(std::string_view name, const std::vector<std::string_view>& candidates);

/// The keys a command takes from its input unless the user sets them (the
/// sensor size: a format's header, --sensor, else a scan of the data).
bool is_taken_from_the_input(std::string_view key);

/// The effective configuration as YAML (every key, current value). Keys for
/// which `commented(key)` holds are written as comments, so that the output
/// read back with --config leaves them unset (--print-config: the keys taken
/// from the input that the user did not set).
std::string to_yaml(const Config& config,
                    const std::function<bool(std::string_view key)>& commented = {});

}  // namespace evlife::config
