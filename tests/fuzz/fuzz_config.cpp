// libFuzzer target: the configuration parser (config/). The input is used
// twice: as a YAML file (ConfigBuilder::load_file) and, line by line, as
// `--set key=value` overrides; then build(). The only acceptable failure is
// ConfigError. Whatever build() accepts must pass the estimator's own
// validation, and must survive a round trip through to_yaml() unchanged.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "evlife/algo/lifetime_options.h"
#include "evlife/config/config.h"
#include "fuzz_input_file.h"

namespace {

void fail(const char* what, const std::string& detail) {
  std::fprintf(stderr, "evlife fuzz: config contract broken: %s\n%s\n", what, detail.c_str());
  std::abort();
}

void check_accepted(const evlife::config::Config& c) {
  const std::string problem = evlife::validate_lifetime_options(c.estimator);
  if (!problem.empty()) fail("build() accepted options the estimator rejects:", problem);
  // Round trip: the effective configuration, written and read back, is the same.
  const std::string yaml = evlife::config::to_yaml(c);
  const std::string& path = evlife::fuzz::write_input_file(
      reinterpret_cast<const std::uint8_t*>(yaml.data()), yaml.size(), ".yaml");
  evlife::config::ConfigBuilder again;
  try {
    again.load_file(path);
    const std::string yaml2 = evlife::config::to_yaml(again.build());
    if (yaml2 != yaml) fail("to_yaml() round trip changed the configuration:", yaml + "---\n" + yaml2);
  } catch (const evlife::config::ConfigError& e) {
    fail("to_yaml() output is not a valid configuration:", yaml + "---\n" + e.what());
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using evlife::config::ConfigBuilder;
  using evlife::config::ConfigError;
  // 1. The input as a YAML file.
  {
    const std::string& path = evlife::fuzz::write_input_file(data, size, ".yaml");
    static bool cleanup = (evlife::fuzz::remove_input_file_at_exit(path), true);
    (void)cleanup;
    ConfigBuilder b;
    try {
      b.load_file(path);
      check_accepted(b.build());
    } catch (const ConfigError& e) {
      if (e.what()[0] == '\0') fail("ConfigError without a message", "");
    }
  }
  // 2. Each line as a --set override, in order.
  {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    ConfigBuilder b;
    std::size_t start = 0;
    while (start <= text.size()) {
      std::size_t end = text.find('\n', start);
      if (end == std::string_view::npos) end = text.size();
      try {
        b.set(text.substr(start, end - start));
      } catch (const ConfigError&) {
        // refused with a message: fine
      }
      start = end + 1;
    }
    try {
      check_accepted(b.build());
    } catch (const ConfigError&) {
    }
  }
  return 0;
}
