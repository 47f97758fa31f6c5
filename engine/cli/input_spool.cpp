#include "input_spool.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <vector>

#include "exit_code.h"

namespace evlife::cli {
namespace {

std::atomic<bool> g_spool_stop{false};
extern "C" void on_spool_signal(int) { g_spool_stop.store(true); }

// The stop signals for the copy, without SA_RESTART so that a read waiting on
// a stalled writer returns EINTR and the copy sees the stop.
class SpoolSignals {
 public:
  SpoolSignals() {
    struct sigaction sa {};
    sa.sa_handler = on_spool_signal;
    sigemptyset(&sa.sa_mask);
    for (std::size_t i = 0; i < kSignals.size(); ++i) sigaction(kSignals[i], &sa, &old_[i]);
  }
  ~SpoolSignals() {
    for (std::size_t i = 0; i < kSignals.size(); ++i) sigaction(kSignals[i], &old_[i], nullptr);
  }
  SpoolSignals(const SpoolSignals&) = delete;
  SpoolSignals& operator=(const SpoolSignals&) = delete;

 private:
  static constexpr std::array<int, 3> kSignals{SIGINT, SIGTERM, SIGHUP};
  std::array<struct sigaction, 3> old_{};
};

std::string stream_name(const std::string& input) { return input == "-" ? std::string("stdin") : input; }

// A named pipe's extension is kept (format sniffing by extension: .dat, .bag).
std::string extension_of(const std::string& input) {
  if (input == "-") return "";
  const std::string ext = std::filesystem::path(input).extension().string();
  return ext.size() <= 8 ? ext : "";
}

}  // namespace

bool InputSpool::needed(const std::string& input) {
  if (input == "-") return true;
  struct stat st {};
  return ::stat(input.c_str(), &st) == 0 && (S_ISFIFO(st.st_mode) || S_ISSOCK(st.st_mode));
}

InputSpool::InputSpool(const std::string& input, const char* command, bool quiet) {
  const std::string name = stream_name(input);
  const char* tmpdir = std::getenv("TMPDIR");
  const std::string ext = extension_of(input);
  std::vector<char> templ;
  for (const char c : std::string(tmpdir != nullptr && *tmpdir != '\0' ? tmpdir : "/tmp") + "/evlife-stdin-XXXXXX" + ext)
    templ.push_back(c);
  templ.push_back('\0');
  const int out = ::mkostemps(templ.data(), static_cast<int>(ext.size()), O_CLOEXEC);
  if (out < 0) {
    const int err = errno;
    throw std::runtime_error(name + ": cannot create a temporary file to hold the stream (" + templ.data() +
                             "): " + std::strerror(err) + "; set TMPDIR to a folder with room");
  }
  path_ = templ.data();
  // Said before the open: a named pipe's open waits for its writer.
  if (!quiet) std::fprintf(stderr, "evlife %s: reading %s into %s (removed at the end)\n", command, name.c_str(), path_.c_str());
  const SpoolSignals signals;
  g_spool_stop.store(false);
  int in = STDIN_FILENO;
  while (input != "-" && (in = ::open(input.c_str(), O_RDONLY | O_CLOEXEC)) < 0) {
    const int err = errno;
    if (err == EINTR && !g_spool_stop.load()) continue;
    ::close(out);
    ::unlink(path_.c_str());
    if (err == EINTR) throw Interrupted{};
    throw std::runtime_error(name + ": cannot open: " + std::strerror(err));
  }
  const auto fail = [&](const std::string& what) {
    ::close(out);
    if (in != STDIN_FILENO) ::close(in);
    ::unlink(path_.c_str());
    throw std::runtime_error(what);
  };
  std::vector<char> buffer(1 << 20);
  auto next_note = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  for (;;) {
    if (g_spool_stop.load()) {
      ::close(out);
      if (in != STDIN_FILENO) ::close(in);
      ::unlink(path_.c_str());
      throw Interrupted{};
    }
    const ssize_t got = ::read(in, buffer.data(), buffer.size());
    if (got < 0) {
      if (errno == EINTR) continue;
      fail(name + ": read failed after " + std::to_string(bytes_) + " bytes: " + std::strerror(errno));
    }
    if (got == 0) break;
    for (ssize_t done = 0; done < got;) {
      const ssize_t put = ::write(out, buffer.data() + done, static_cast<std::size_t>(got - done));
      if (put < 0) {
        if (errno == EINTR) continue;
        fail(name + ": cannot copy the stream into " + path_ + " after " + std::to_string(bytes_) +
             " bytes: " + std::strerror(errno) + "; set TMPDIR to a folder with room, or save it to a file");
      }
      done += put;
    }
    bytes_ += static_cast<std::uint64_t>(got);
    if (!quiet && std::chrono::steady_clock::now() >= next_note) {
      std::fprintf(stderr, "evlife %s: %.1f MB of %s read\n", command, static_cast<double>(bytes_) / 1e6, name.c_str());
      next_note += std::chrono::seconds(10);
    }
  }
  if (::close(out) != 0) {
    const int err = errno;
    if (in != STDIN_FILENO) ::close(in);
    ::unlink(path_.c_str());
    throw std::runtime_error(name + ": cannot copy the stream into " + path_ + ": " + std::strerror(err));
  }
  if (in != STDIN_FILENO) ::close(in);
}

InputSpool::~InputSpool() { ::unlink(path_.c_str()); }

std::optional<int> spool_stream_input(const char* command, std::string& input, bool quiet,
                                      std::optional<InputSpool>& spool) {
  if (!InputSpool::needed(input)) return std::nullopt;
  try {
    spool.emplace(input, command, quiet);
  } catch (const InputSpool::Interrupted&) {
    std::fprintf(stderr, "evlife %s: interrupted while reading %s: nothing processed\n", command,
                 stream_name(input).c_str());
    return kExitInterrupted;
  } catch (const std::runtime_error& e) {
    std::fprintf(stderr, "evlife %s: input error: %s\n", command, e.what());
    return kExitInput;
  }
  input = spool->path();
  return std::nullopt;
}

}  // namespace evlife::cli
