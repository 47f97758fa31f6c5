// Subcommand registry of the `evlife` CLI. Each cmd_<name>.cpp registers
// itself with a static EVLIFE_REGISTER_COMMAND, so commands land independently,
// and keeps its private names (kOptions, print_help, ...) in namespace
// evlife::cli::<name>_command: a unity build compiles several cmd files as one.
#pragma once

#include <string_view>
#include <vector>

namespace evlife::cli {

struct Command {
  std::string_view name;     // e.g. "process"
  std::string_view summary;  // one line for `evlife --help`
  int (*run)(int argc, char** argv);  // argv[0] is the subcommand name
};

std::vector<Command>& command_registry();

/// "0.1.0 (git v0.1-12-gabcdef)": `evlife --version` and `evlife CMD --version`.
const char* version_text();

inline bool register_command(const Command& command) {
  command_registry().push_back(command);
  return true;
}

}  // namespace evlife::cli

#define EVLIFE_REGISTER_COMMAND(name, summary, fn)                    \
  [[maybe_unused]] static const bool evlife_registered_##fn =         \
      ::evlife::cli::register_command({name, summary, &(fn)})
