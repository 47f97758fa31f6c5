// Runs the `evlife` binary as a user would, for the CLI tests.
#pragma once

#include <filesystem>
#include <string>

#include "evlife/io/synthetic_scene.h"

namespace evlife::test {

struct CliRun {
  int exit_code = -1;   ///< -1 when the process did not exit normally
  std::string output;   ///< stdout and stderr together
};

/// Runs `'cli' args` through the shell with no stdin, capturing both streams
/// in `log_stem`.<pid> (removed afterwards) and returning them.
CliRun run_cli(const std::string& cli, const std::string& args, const std::filesystem::path& log_stem);

/// The whole file, or "" when it cannot be read.
std::string read_text_file(const std::filesystem::path& path);

/// MemAvailable, what the CLI weighs its memory refusals against.
using io::available_memory_bytes;

}  // namespace evlife::test
