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

#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "evlife/algo/lifetime_options.h"

namespace evlife::config {

/// YAML section `engine:` (`evlife run`): thread roles, tiling, queue sizes,
/// overload policy. Plain values, mapped onto evlife::engine::EngineOptions
/// by the CLI (config does not depend on the engine); defaults equal
/// EngineOptions' (test_engine checks).
struct EngineSection {
  int workers = 2;                ///< worker threads, 1..32
  int tiles_x = 1;                ///< tiles per polarity, columns, 1..256
  int tiles_y = 1;                ///< tiles per polarity, rows, 1..256
  int margin_px = -1;             ///< -1 = auto (4 x window size), 0..1024
  int batch_events = 1024;        ///< events per batch through the queues, 16..65536
  int batches_per_worker = 64;    ///< batches in flight per worker, 2..1024
  std::string policy = "auto";    ///< auto | block | drop
  double stats_period_s = 1.0;    ///< progress line period, 0 = none
  int idle_spin_us = -1;          ///< idle worker polls this long before sleeping; -1 auto, 0..100000
  int replay_packet_us = 100;     ///< paced replays: packet period, 0..1000000 (0 = none)
};

struct Config {
  LifetimeOptions estimator;  ///< YAML section `estimator:`, 1:1 with LifetimeOptions
  EngineSection engine;       ///< YAML section `engine:`
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

  /// Same for one key and its value, `where` naming the origin in messages
  /// (e.g. a Python keyword argument). Throws ConfigError as set() does.
  void set(std::string_view key, std::string_view value, const std::string& where);

  /// Validates every key once; throws ConfigError naming the first bad key,
  /// its value, where it was set and the allowed range.
  Config build() const;

  /// Non-null when the key was given by a file or --set.
  const KeyOrigin* origin(std::string_view key) const;

 private:
  void assign(std::string_view key, std::string_view value, const std::string& where,
              bool by_user);

  Config config_;
  std::map<std::string, KeyOrigin, std::less<>> origins_;
};

/// Path of the documented default file compiled into the library.
std::string default_config_path();

/// Convenience: defaults, then `path` (if not empty), then overrides; validated.
Config load_config(const std::string& path, const std::vector<std::string>& overrides = {});

/// The effective configuration as YAML (every key, current value).
std::string to_yaml(const Config& config);

}  // namespace evlife::config
