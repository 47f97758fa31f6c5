// `evlife <command> [args]`: dispatches to the registered subcommands.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string_view>

#include "command.h"

namespace evlife::cli {
std::vector<Command>& command_registry() {
  static std::vector<Command> registry;
  return registry;
}
}  // namespace evlife::cli

namespace {
void print_usage(std::FILE* out) {
  auto commands = evlife::cli::command_registry();
  std::sort(commands.begin(), commands.end(),
            [](const auto& a, const auto& b) { return a.name < b.name; });
  std::fprintf(out,
               "evlife — event lifetime estimation (Mueggler et al., ICRA 2015)\n\n"
               "Usage: evlife <command> [options]    (evlife <command> --help for details)\n\n"
               "Commands:\n");
  for (const auto& c : commands) {
    std::fprintf(out, "  %-10.*s %.*s\n", static_cast<int>(c.name.size()), c.name.data(),
                 static_cast<int>(c.summary.size()), c.summary.data());
  }
}
}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0) {
    print_usage(argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  const std::string_view name = argv[1];
  for (const auto& c : evlife::cli::command_registry()) {
    if (c.name == name) return c.run(argc - 1, argv + 1);
  }
  std::fprintf(stderr, "evlife: unknown command '%s'\n\n", argv[1]);
  print_usage(stderr);
  return 2;
}
