// The start every command shares: `--help`/`-h` anywhere prints the help and
// ends with 0 (`--version` the version); otherwise `parse()` runs, and a usage or configuration error is
// printed as "evlife <command>: ..." and ends with status 2.
#pragma once

#include <cstdio>
#include <optional>
#include <string_view>

#include "arg_parser.h"
#include "command.h"
#include "evlife/config/config.h"
#include "exit_code.h"

namespace evlife::cli {

/// Returns the exit status to end the command with, or nullopt to go on.
template <typename Parse>
std::optional<int> start_command(const char* command, int argc, char** argv, void (*help)(std::FILE*),
                                 Parse&& parse) {
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      help(stdout);
      return kExitOk;
    }
    if (arg == "--version") {
      std::printf("evlife %s\n", version_text());
      return kExitOk;
    }
  }
  try {
    parse();
  } catch (const UsageError& e) {
    return usage_exit(command, e.what());
  } catch (const config::ConfigError& e) {
    std::fprintf(stderr, "evlife %s: configuration error: %s\n", command, e.what());
    return kExitUsage;
  }
  return std::nullopt;
}

}  // namespace evlife::cli
