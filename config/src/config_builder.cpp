// Loads YAML files and --set overrides into a Config, remembering where each
// key was set so that every error can name the key, its origin and its range.
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "evlife/config/config.h"
#include "evlife/config/config_key.h"
#include "evlife/engine/engine_options.h"
#include "evlife/io/installed_file.h"
#include "key_helpers.h"

namespace evlife::config {
namespace {

// A configuration larger than this is no configuration (a pipe that never ends).
constexpr std::size_t kMaxConfigBytes = std::size_t{16} << 20;

// The whole file, read once: a pipe (`--config <(...)`, /dev/stdin) or a FIFO
// is read once only (each later open found it empty, or waited for a writer).
std::string read_config_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError(path + ": cannot read the configuration file: " + std::strerror(errno));
  std::string text;
  char buffer[4096];
  while (in.read(buffer, sizeof buffer) || in.gcount() > 0) {
    text.append(buffer, static_cast<std::size_t>(in.gcount()));
    if (text.size() > kMaxConfigBytes)
      throw ConfigError(path + ": more than " + std::to_string(kMaxConfigBytes >> 20) + " MiB: not a configuration file");
  }
  if (in.bad()) throw ConfigError(path + ": cannot read the configuration file: " + std::strerror(errno));
  return text;
}

// Offset of the first NUL byte in `text` (-1: none). A configuration is text;
// a binary file is not worth parsing. UTF-16 and UTF-32 text is YAML's too
// (PowerShell writes UTF-16): YAML tells them by a NUL among the first 4
// bytes or a byte-order mark, and so does this.
std::int64_t first_nul_byte(std::string_view text) {
  const std::string_view start = text.substr(0, 4);
  if (start.find('\0') != std::string_view::npos || start.starts_with("\xFF\xFE") || start.starts_with("\xFE\xFF"))
    return -1;
  const std::size_t at = text.find('\0');
  return at == std::string_view::npos ? -1 : static_cast<std::int64_t>(at);
}

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

}  // namespace

std::string closest_name(std::string_view name, const std::vector<std::string_view>& candidates) {
  std::string_view best;
  std::size_t best_d = 4;  // suggest only close matches
  for (const auto c : candidates) {
    const std::size_t d = edit_distance(name, c);
    if (d < best_d) {
      best_d = d;
      best = c;
    }
  }
  return std::string(best);
}

namespace {

// True when `prefix` names a section (some key lies below it).
bool is_section(std::string_view prefix) {
  for (const auto& k : config_keys()) {
    if (k.name.size() > prefix.size() && k.name.compare(0, prefix.size(), prefix) == 0 &&
        k.name[prefix.size()] == '.') {
      return true;
    }
  }
  return false;
}

std::string unknown_key_message(const std::string& where, std::string_view key) {
  std::ostringstream msg;
  msg << where << ": unknown configuration key '" << key << "'";
  std::vector<std::string_view> all;
  for (const auto& k : config_keys()) all.push_back(k.name);
  if (const std::string best = closest_name(key, all); !best.empty())
    msg << " (did you mean '" << best << "'?)";
  // List the keys of the same top-level section, else the sections.
  const std::string section(key.substr(0, key.find('.')));
  const bool known_section = is_section(section);
  std::vector<std::string> names;
  for (const auto& k : config_keys()) {
    const std::string top = k.name.substr(0, k.name.find('.'));
    if (known_section && top != section) continue;
    std::string name = known_section ? k.name.substr(top.size() + 1) : top;
    if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
  }
  msg << (known_section ? "; keys of '" + section + "':" : std::string("; sections:"));
  for (std::size_t i = 0; i < names.size(); ++i) msg << (i == 0 ? " " : ", ") << names[i];
  return msg.str();
}

std::string trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(" \t\r\n");
  return std::string(s.substr(b, e - b + 1));
}

}  // namespace

ConfigBuilder::ConfigBuilder() = default;

void ConfigBuilder::assign(std::string_view key, std::string_view value, const std::string& where,
                           bool by_user) {
  const ConfigKey* k = find_config_key(key);
  if (!k) throw ConfigError(unknown_key_message(where, key));
  if (!k->parse(config_, value)) {
    // A whole number beyond the field's type (2^31 for an int) is out of range, as 100 is, not "no integer".
    if (k->type == "integer" && detail::is_integer_text(value, k->hex)) {
      throw ConfigError(where + ": " + std::string(key) + " = " + std::string(value) + " is out of range; allowed: " +
                        k->allowed);
    }
    // "0x2" or "2.0" is a number, but not in the form an integer key takes: say which it takes.
    const char* digits = k->type != "integer" ? "" : k->hex ? "decimal or 0x hex digits; " : "decimal digits; ";
    throw ConfigError(where + ": " + std::string(key) + " = '" + std::string(value) + "' is not a valid " + k->type +
                      " (" + digits + "allowed: " + k->allowed + ")");
  }
  origins_[std::string(key)] = KeyOrigin{where, by_user};
}

namespace {

/// Where a stream's YAML documents start, the first two. yaml-cpp 0.7's
/// LoadAll loops for ever, allocating, on a document that begins with a ','
/// outside brackets (its parser never moves past it; fuzz_config found it):
/// that shows here as a second document starting where the first did.
struct DocumentStarts final : YAML::EventHandler {
  std::vector<YAML::Mark> starts;
  void OnDocumentStart(const YAML::Mark& mark) override { starts.push_back(mark); }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t, const std::string&) override {}
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}
};

std::vector<YAML::Mark> first_two_document_starts(const std::string& text) {
  std::istringstream in(text);
  YAML::Parser parser(in);
  DocumentStarts starts;
  while (starts.starts.size() < 2 && parser.HandleNextDocument(starts)) {
  }
  return starts.starts;
}

}  // namespace

void ConfigBuilder::load_file(const std::string& path, bool by_user) {
  // The non-throwing checks: a symlink loop, a name too long or a folder not
  // to be searched is the file's fault, said so (it was an "unexpected error").
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(path, error);
  if (error && error != std::errc::no_such_file_or_directory) {
    throw ConfigError(path + ": cannot read the configuration file: " + error.message());
  }
  if (!std::filesystem::exists(status)) {
    throw ConfigError(path + ": configuration file not found");
  }
  if (std::filesystem::is_directory(status)) {
    throw ConfigError(path + ": is a directory, not a configuration file");
  }
  const std::string text = read_config_text(path);
  if (const std::int64_t at = first_nul_byte(text); at >= 0) {  // yaml-cpp would name an odd escape
    throw ConfigError(path + ": not a YAML text file (a NUL byte at offset " + std::to_string(at) + ")");
  }
  std::vector<YAML::Mark> starts;  // of the first two documents
  YAML::Node root;
  try {
    starts = first_two_document_starts(text);
    if (starts.size() == 2 && starts[1].pos == starts[0].pos) {
      throw ConfigError(path + ":" + std::to_string(starts[0].line + 1) +
                        ": YAML syntax error: the file cannot be read past this point (a ',' outside brackets?)");
    }
    if (starts.empty()) return;  // empty file: defaults stand
    root = YAML::Load(text);  // the first document
  } catch (const YAML::Exception& e) {
    throw ConfigError(path + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax error: " +
                      e.msg);
  } catch (const ConfigError&) {
    throw;
  } catch (const std::exception& e) {  // yaml-cpp reads with a stream: unreadable files
    throw ConfigError(path + ": cannot read the configuration file: " + e.what());
  }
  auto where = [&](const YAML::Node& n) {
    return path + ":" + std::to_string(n.Mark().line + 1);
  };
  // Before a second document: what else follows a first line that is no map
  // (an INI file's "[estimator]" is a YAML list) says nothing more.
  if (!root.IsNull() && !root.IsMap()) {
    throw ConfigError(where(root) + ": expected a map of sections at top level (" +
                      (root.IsSequence() ? "an INI-style [section] is a YAML list; " : "") +
                      "write 'estimator:' and its keys indented below it)");
  }
  if (starts.size() > 1) {
    throw ConfigError(path + ":" + std::to_string(starts[1].line + 1) +
                      ": a second YAML document: a configuration file holds one");
  }
  if (root.IsNull()) return;  // only comments: defaults stand

  // Depth-first over maps; leaves are scalars named by their dotted path.
  // yaml-cpp keeps a key written twice: the second one is an error here, not
  // a silent winner (nor a section merged from two places).
  std::map<std::string, int, std::less<>> line_of_key;
  auto walk = [&](auto&& self, const YAML::Node& map, const std::string& prefix) -> void {
    for (const auto& item : map) {
      // A key must be a name: YAML also allows empty, sequence and map keys,
      // which as<std::string>() would throw on (a fuzzer found one).
      if (!item.first.IsScalar()) throw ConfigError(where(item.first) + ": expected a key name");
      const std::string name = item.first.as<std::string>();
      const std::string key = prefix.empty() ? name : prefix + "." + name;
      const YAML::Node& value = item.second;
      const bool section = is_section(key);
      if (!section && !find_config_key(key)) throw ConfigError(unknown_key_message(where(item.first), key));
      if (const auto [it, first] = line_of_key.emplace(key, item.first.Mark().line + 1); !first) {
        throw ConfigError(where(item.first) + ": " + key + " is already given at line " +
                          std::to_string(it->second));
      }
      if (section) {
        if (value.IsMap()) {
          self(self, value, key);
        } else if (!value.IsNull()) {  // null: every key of it commented out
          throw ConfigError(where(item.first) + ": " + key + " is a section: expected its keys, indented below it");
        }
      } else if (value.IsScalar()) {
        assign(key, value.Scalar(), where(item.first), by_user);
      } else {
        throw ConfigError(where(item.first) + ": " + key +
                          (value.IsNull() ? " has no value" : " must be a single value"));
      }
    }
  };
  walk(walk, root, "");
}

std::string ConfigBuilder::load_default_file_if_present() {
  const std::string path = default_config_path();
  std::error_code error;  // (unreadable: load_file says why)
  if (path.empty() || (!std::filesystem::exists(path, error) && !error)) return {};
  load_file(path, /*by_user=*/false);
  return path;
}

std::string ConfigBuilder::key_of_assignment(std::string_view assignment) {
  return trim(assignment.substr(0, assignment.find('=')));
}

void ConfigBuilder::set(std::string_view assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string_view::npos) {
    throw ConfigError("--set " + std::string(assignment) + ": expected key=value, e.g. --set " +
                      "estimator.window_size=7");
  }
  const std::string key = key_of_assignment(assignment);
  std::string value = trim(assignment.substr(eq + 1));
  if (value.size() >= 2 && (value.front() == '"' || value.front() == '\'') &&
      value.back() == value.front()) {
    value = value.substr(1, value.size() - 2);
  }
  assign(key, value, "--set " + std::string(assignment), /*by_user=*/true);
}

void ConfigBuilder::set(std::string_view key, std::string_view value, const std::string& where) {
  assign(key, value, where, /*by_user=*/true);
}

Config ConfigBuilder::build() const {
  for (const auto& k : config_keys()) {
    if (!k.in_range(config_)) {
      const KeyOrigin* o = origin(k.name);
      throw ConfigError(k.name + " = " + k.format(config_) + " (" +
                        (o ? "set at " + o->where : std::string("default")) +
                        ") is out of range; allowed: " + k.allowed);
    }
  }
  const auto set_at = [&](std::string_view key) {
    const KeyOrigin* o = origin(key);
    return o ? "set at " + o->where : std::string("default");
  };
  if (const auto problem = engine::stats_period_problem(config_.engine.stats_period_s)) {
    throw ConfigError("engine.stats_period_s = " + find_config_key("engine.stats_period_s")->format(config_) + " (" +
                      set_at("engine.stats_period_s") + ") " + *problem);
  }
  // A sensor size is both keys or neither: one alone would pair with the
  // other's default (128) instead of the size the input gives.
  const bool width_set = origin("estimator.sensor.width") != nullptr;
  if (width_set != (origin("estimator.sensor.height") != nullptr)) {
    const char* set = width_set ? "estimator.sensor.width" : "estimator.sensor.height";
    const char* unset = width_set ? "estimator.sensor.height" : "estimator.sensor.width";
    throw ConfigError(std::string(set) + " is " + set_at(set) + ", " + unset +
                      " is not: set both, or neither (the size then comes from the input or --sensor)");
  }
  // The estimator's rule across fields (continuation_min_support within
  // window_size's window): where both were set, as for a range.
  const std::string err = validate_lifetime_options(config_.estimator);
  if (!err.empty()) {
    std::string where;
    for (const char* key : {"estimator.continuation_min_support", "estimator.window_size"}) {
      const KeyOrigin* o = origin(key);
      where += (where.empty() ? " (" : "; ") + std::string(key) + (o ? " set at " + o->where : " default");
    }
    throw ConfigError("estimator." + err + where + ")");
  }
  return config_;
}

const KeyOrigin* ConfigBuilder::origin(std::string_view key) const {
  const auto it = origins_.find(key);
  return it == origins_.end() ? nullptr : &it->second;
}

const KeyOrigin* ConfigBuilder::user_origin_of_input_keys() const {
  for (const auto& [key, where] : origins_) {
    if (where.by_user && is_taken_from_the_input(key)) return &where;
  }
  return nullptr;
}

namespace {
std::atomic<bool> g_installed_configuration{false};
}  // namespace

void use_installed_configuration() { g_installed_configuration.store(true); }

std::string default_config_path() {
  // An installed tool reads its own copy (share/evlife/ beside bin/), a build tree the source's.
  if (g_installed_configuration.load()) {
    if (std::string installed = io::installed_file(EVLIFE_INSTALLED_CONFIG); !installed.empty()) return installed;
  }
#ifdef EVLIFE_DEFAULT_CONFIG
  return EVLIFE_DEFAULT_CONFIG;
#else
  return {};
#endif
}

LoadedConfig load_config(const std::string& path, const std::vector<std::string>& overrides) {
  LoadedConfig c;
  if (!path.empty()) {
    c.builder.load_file(path);
    c.source = path;
  } else {
    c.source = c.builder.load_default_file_if_present();
    if (c.source.empty()) c.source = "built-in defaults";
  }
  c.overrides = overrides;
  for (const auto& o : overrides) c.builder.set(o);
  c.config = c.builder.build();
  return c;
}

std::string LoadedConfig::describe() const {
  std::string s = source;
  for (const auto& o : overrides) s += ", --set " + o;
  return s;
}

bool is_taken_from_the_input(std::string_view key) {
  return key == "estimator.sensor.width" || key == "estimator.sensor.height";
}

std::string to_yaml(const Config& config, const std::function<bool(std::string_view key)>& commented) {
  // Keys are listed section by section, so emit a nested map in that order.
  std::ostringstream out;
  std::vector<std::string> open;  // currently open map path
  for (const auto& k : config_keys()) {
    std::vector<std::string> parts;
    std::size_t start = 0;
    for (std::size_t dot; (dot = k.name.find('.', start)) != std::string::npos; start = dot + 1) {
      parts.push_back(k.name.substr(start, dot - start));
    }
    const std::string leaf = k.name.substr(start);
    std::size_t common = 0;
    while (common < open.size() && common < parts.size() && open[common] == parts[common]) ++common;
    open.resize(common);
    for (std::size_t i = common; i < parts.size(); ++i) {
      out << std::string(2 * i, ' ') << parts[i] << ":\n";
      open.push_back(parts[i]);
    }
    const bool as_comment = commented && commented(k.name);
    out << std::string(2 * parts.size(), ' ') << (as_comment ? "# " : "") << leaf << ": "
        << k.format(config) << "\n";
  }
  return out.str();
}

}  // namespace evlife::config
