#include "input_spool.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <vector>

#include "evlife/io/temp_dir.h"
#include "exit_code.h"
#include "stop_signals.h"

namespace evlife::cli {
namespace {

// "stdin", or a named pipe's file name: its extension still counts (format
// sniffing by extension: .dat, .bag).
std::string copy_name(const std::string& input) {
  if (input == "-") return "stdin";
  const std::string name = std::filesystem::path(input).filename().string();
  return name.empty() || name == "." || name == ".." ? "stream" : name;
}

// Closes a descriptor it owns (not stdin) on every way out.
struct Descriptor {
  int fd = -1;
  ~Descriptor() {
    if (fd > STDIN_FILENO) ::close(fd);
  }
};

}  // namespace

bool InputSpool::needed(const std::string& input) {
  if (input == "-") return true;
  struct stat st {};
  return ::stat(input.c_str(), &st) == 0 && (S_ISFIFO(st.st_mode) || S_ISSOCK(st.st_mode));
}

InputSpool::InputSpool(const std::string& input, const char* command, bool quiet)
    : stream_(stream_name(input)) {
  // The copy lives in a private folder under the stream's own name ("stdin",
  // or the pipe's file name: its extension tells some formats); messages
  // name it as the stream itself (name_, from the open on).
  std::string folder = io::temp_dir() + "/evlife-XXXXXX";
  if (::mkdtemp(folder.data()) == nullptr) {
    throw std::runtime_error(stream_ + ": cannot create a temporary folder to hold the stream (" + folder +
                             "): " + std::strerror(errno) + "; set TMPDIR to a folder with room");
  }
  folder_ = folder;
  path_ = folder_ + "/" + copy_name(input);
  name_.emplace(path_, stream_);
  Descriptor out{::open(path_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600)};
  if (out.fd < 0) {
    const int err = errno;
    ::rmdir(folder_.c_str());
    throw std::runtime_error(stream_ + ": cannot create " + path_ + " to hold the stream: " + std::strerror(err));
  }
  try {
    copy(input, out.fd, command, quiet);
  } catch (...) {
    remove_copy();  // the destructor does not run for a constructor that throws
    throw;
  }
  const int closed = ::close(out.fd);
  out.fd = -1;
  if (closed != 0) {
    const int err = errno;
    remove_copy();
    throw std::runtime_error(stream_ + ": cannot copy the stream into " + path_ + ": " + std::strerror(err));
  }
}

void InputSpool::copy(const std::string& input, int out, const char* command, bool quiet) {
  // Said before the open: a named pipe's open waits for its writer.
  if (!quiet) std::fprintf(stderr, "evlife %s: reading %s into %s (removed at the end)\n", command, stream_.c_str(), path_.c_str());
  const StopRequest stop(/*interrupt_calls=*/true);  // a read waiting on a stalled writer sees Ctrl-C
  Descriptor in{STDIN_FILENO};
  while (input != "-" && (in.fd = ::open(input.c_str(), O_RDONLY | O_CLOEXEC)) < 0) {
    if (errno != EINTR) throw std::runtime_error(stream_ + ": cannot open: " + std::strerror(errno));
    if (stop.requested()) throw Interrupted{};
  }
  std::vector<char> buffer(1 << 20);
  auto next_note = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  for (;;) {
    if (stop.requested()) throw Interrupted{};
    const ssize_t got = ::read(in.fd, buffer.data(), buffer.size());
    if (got < 0) {
      if (errno == EINTR) continue;
      throw std::runtime_error(stream_ + ": read failed after " + std::to_string(bytes_) + " bytes: " + std::strerror(errno));
    }
    if (got == 0) return;
    for (ssize_t done = 0; done < got;) {
      const ssize_t put = ::write(out, buffer.data() + done, static_cast<std::size_t>(got - done));
      if (put < 0) {
        if (errno == EINTR) continue;
        throw std::runtime_error(stream_ + ": cannot copy the stream into " + path_ + " after " +
                                 std::to_string(bytes_) + " bytes: " + std::strerror(errno) +
                                 "; set TMPDIR to a folder with room, or save it to a file");
      }
      done += put;
    }
    bytes_ += static_cast<std::uint64_t>(got);
    if (!quiet && std::chrono::steady_clock::now() >= next_note) {
      std::fprintf(stderr, "evlife %s: %.1f MB of %s read\n", command, static_cast<double>(bytes_) / 1e6, stream_.c_str());
      next_note += std::chrono::seconds(10);
    }
  }
}

std::string InputSpool::as_argument(const std::string& input) {
  const std::string name = io::name_in_messages(input);
  return name != input && name == stream_name("-") ? "-" : name;
}

void InputSpool::remove_copy() noexcept {
  ::unlink(path_.c_str());
  ::rmdir(folder_.c_str());
  name_.reset();
}

InputSpool::~InputSpool() { remove_copy(); }

std::optional<int> spool_stream_input(const char* command, std::string& input, bool quiet,
                                      std::optional<InputSpool>& spool) {
  if (!InputSpool::needed(input)) return std::nullopt;
  try {
    spool.emplace(input, command, quiet);
  } catch (const InputSpool::Interrupted&) {
    std::fprintf(stderr, "evlife %s: interrupted while reading %s: nothing processed\n", command,
                 InputSpool::stream_name(input).c_str());
    return kExitInterrupted;
  } catch (const std::runtime_error& e) {
    std::fprintf(stderr, "evlife %s: input error: %s\n", command, e.what());
    return kExitInput;
  }
  input = spool->path();
  return std::nullopt;
}

}  // namespace evlife::cli
