// `evlife <command> [args]`: dispatches to the registered subcommands.
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <exception>
#include <new>
#include <string_view>

#include "command.h"
#include "evlife/engine/exit_code.h"
#include "evlife/config/config.h"
#include "evlife/io/hdf5_writer.h"
#include "evlife/io/stop.h"
#include "stop_signals.h"

namespace evlife::cli {
std::vector<Command>& command_registry() {
  static std::vector<Command> registry;
  return registry;
}

const char* version_text() {
#ifdef EVLIFE_VERSION
  return EVLIFE_VERSION;
#else
  return "unknown";
#endif
}
}  // namespace evlife::cli

namespace {
// The configuration read without --config: its path, or the built-in defaults when it is absent.
std::string default_config_text() {
  const std::string path = evlife::config::default_config_path();
  std::error_code ec;
  if (!path.empty() && std::filesystem::exists(path, ec)) return path;
  return "the built-in defaults" + (path.empty() ? std::string{} : " (" + path + " is absent)");
}

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
  std::fprintf(out,
               "\nExamples:\n"
               "  evlife synth -o sample.txt                      # a synthetic recording with known truth\n"
               "  evlife process sample.txt -o sample.csv         # lifetime + velocity for every event\n"
               "  evlife render recording.mat -o f.png --at 0.5 --mode compare   # 1 ms | 30 ms | lifetime\n"
               "  evlife run --source dvs128 -o live.bin          # live DVS128, real-time engine\n"
               "\nEvery event is active from t to t + lifetime, so a sharp edge image exists at any instant.\n"
               "Every command takes --help and --version, and all but synth and devices take\n"
               "-i/--input FILE (or FILE); those that estimate take --config FILE, --set key=value\n"
               "and --print-config (without --config: %s).\n"
               "Times: 1.5s, 500ms, 20us, or a bare number of seconds. Exit status 0 ok,\n"
               "1 unexpected failure (devices: libusb cannot start), 2 usage, 3 input error,\n"
               "4 output error, 5 a real-time setting refused (run), 130 interrupted.\n",
               default_config_text().c_str());
}

// True when stdout is a pipe whose reader has left (poll flags its write end).
bool stdout_reader_left() {
  pollfd out{STDOUT_FILENO, 0, 0};
  return errno == EPIPE || (::poll(&out, 1, 0) == 1 && (out.revents & POLLERR) != 0);
}

// What a command printed must reach its reader: a full disk or a closed pipe
// behind stdout (`evlife info x > /dev/full`) is an output error, not exit 0.
// A reader that left on purpose (`evlife convert --help | head`) needs no
// message: exit 4 only.
int with_stdout_written(const char* command, int code) {
  errno = 0;
  if (std::fflush(stdout) == 0 && !std::ferror(stdout)) return code;
  if (!stdout_reader_left()) {
    std::fprintf(stderr, "evlife%s%s: cannot write the standard output: %s\n", command[0] ? " " : "", command,
                 errno != 0 ? std::strerror(errno) : "write error");
  }
  return code == 0 ? evlife::kExitOutput : code;
}
}  // namespace

int main(int argc, char** argv) {
  // A reader leaving a pipe (`-o fifo`, `evlife info x | head`) makes the next
  // write fail with EPIPE, reported as any output error (exit 4, the output
  // named, what was written kept), instead of killing the process silently.
  std::signal(SIGPIPE, SIG_IGN);
  // Likewise a file size limit (ulimit -f): the write that passes it fails
  // with EFBIG, an output error (the file cut back to its last whole record,
  // an HDF5 file closed, a PNG removed), instead of SIGXFSZ killing the
  // process silently with a cut file.
  std::signal(SIGXFSZ, SIG_IGN);
  // A write to a FIFO whose reader takes nothing, and the decompression of a
  // file-compressed bag, give up on a stop signal (io/stop.h).
  evlife::io::set_stop_flag(&evlife::cli::g_stop_requested);
  evlife::config::use_installed_configuration();
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0) {
    print_usage(argc < 2 ? stderr : stdout);
    return with_stdout_written("", argc < 2 ? 2 : 0);
  }
  if (std::strcmp(argv[1], "--version") == 0 || std::strcmp(argv[1], "-V") == 0) {
    std::printf("evlife %s\n", evlife::cli::version_text());
    return with_stdout_written("", 0);
  }
  // `evlife help CMD` is `evlife CMD --help`.
  char help_flag[] = "--help";
  char* help_argv[] = {argv[0], argc > 2 ? argv[2] : nullptr, help_flag, nullptr};
  if (std::strcmp(argv[1], "help") == 0) {
    if (argc < 3 || std::strcmp(argv[2], "help") == 0 || argv[2][0] == '-') {  // `help`, `help --help`
      print_usage(stdout);
      return with_stdout_written("", 0);
    }
    argc = 3;
    argv = help_argv;
  }
  const std::string_view name = argv[1];
  for (const auto& c : evlife::cli::command_registry()) {
    if (c.name != name) continue;
    int code = 1;  // kExitFailure
    try {
      code = c.run(argc - 1, argv + 1);
    } catch (const std::bad_alloc&) {
      std::fprintf(stderr, "evlife %s: out of memory (a large --sensor, --scale or number of workers?)\n", argv[1]);
    } catch (const std::exception& e) {  // a bug or out of memory: a message, never a crash
      std::fprintf(stderr, "evlife %s: unexpected error: %s\n", argv[1], e.what());
    }
    code = with_stdout_written(argv[1], code);
    // libhdf5 1.10's exit handler would crash (a failed close) or loop and print noise (a failed create).
    if (evlife::io::hdf5_exit_would_crash() || evlife::io::hdf5_exit_would_loop()) {
      std::fflush(nullptr);
      std::_Exit(code);
    }
    return code;
  }
  std::vector<std::string_view> names;
  for (const auto& c : evlife::cli::command_registry()) names.push_back(c.name);
  const std::string best = evlife::config::closest_name(name, names);
  std::fprintf(stderr, "evlife: unknown command '%s'%s%s%s\n\n", argv[1],
               best.empty() ? "" : " (did you mean '", best.c_str(), best.empty() ? "" : "'?)");
  print_usage(stderr);
  return 2;
}
