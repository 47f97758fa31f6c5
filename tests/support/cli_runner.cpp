#include "cli_runner.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

namespace evlife::test {

CliRun run_cli(const std::string& cli, const std::string& args, const std::filesystem::path& log_stem) {
  // ctest runs each test case as its own process, two at a time: a log path
  // shared by the cases of one file would let one case read another's output.
  const std::filesystem::path log = log_stem.string() + "." + std::to_string(::getpid());
  const std::string cmd = "'" + cli + "' " + args + " >'" + log.string() + "' 2>&1 </dev/null";
  const int status = std::system(cmd.c_str());
  CliRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.output = read_text_file(log);
  std::error_code ignored;
  std::filesystem::remove(log, ignored);
  return r;
}

std::string read_text_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return {};
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace evlife::test
