// Runs the `evlife` binary as a user would, for the CLI tests.
#pragma once

#include <algorithm>
#include <filesystem>
#include <string>
#include <string_view>

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

/// Whether `output` names a path in `temp_dir`: the temporary copy of a
/// stream (`-`, a named pipe) that messages are to name as the user gave it.
/// `evlife info`'s "file  stdin (a stream, read from its copy …)" line does
/// not count: it says what the path is.
inline bool names_a_stream_copy(const std::string& output, const std::filesystem::path& temp_dir) {
  for (std::size_t begin = 0, end; begin < output.size(); begin = end + 1) {
    end = std::min(output.find('\n', begin), output.size());
    const std::string_view line = std::string_view(output).substr(begin, end - begin);
    if (line.find(temp_dir.string()) != line.npos && line.find("read from its copy") == line.npos) return true;
  }
  return false;
}

/// MemAvailable, what the CLI weighs its memory refusals against.
using io::available_memory_bytes;

}  // namespace evlife::test
