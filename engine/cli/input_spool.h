// INPUT `-` (stdin), a named pipe or a process substitution (`<(unzip -p
// x.zip events.txt)`): the readers read a file's start again once they know
// its format, and several formats need its size, so such a stream is first
// copied into a temporary file (`$TMPDIR/evlife-XXXXXX/stdin`, else under
// /tmp; a pipe's copy keeps the pipe's file name), which the readers then
// take as INPUT and which is removed when the command ends. Messages name the
// copy as the stream (`stdin`, the pipe's path as given: io::StreamCopyName).
// Formats are then recognised by their content (text, CSV, AEDAT, Prophesee
// RAW, MATLAB, HDF5); a named pipe's own extension still counts (x.dat, x.bag).
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "evlife/io/stream_copy_name.h"

namespace evlife::cli {

class InputSpool {
 public:
  /// True for `-` and for paths that are pipes or sockets.
  static bool needed(const std::string& input);

  /// Copies the stream. Throws std::runtime_error naming the stream and the
  /// temporary file (read error, full disk); Ctrl-C (SIGINT, SIGTERM, SIGHUP)
  /// while it reads throws Interrupted. Progress lines on stderr unless quiet.
  InputSpool(const std::string& input, const char* command, bool quiet);
  ~InputSpool();
  InputSpool(const InputSpool&) = delete;
  InputSpool& operator=(const InputSpool&) = delete;

  const std::string& path() const noexcept { return path_; }
  /// What the stream is called: "stdin" or the pipe's path.
  const std::string& stream() const noexcept { return stream_; }
  static std::string stream_name(const std::string& input) { return input == "-" ? "stdin" : input; }
  /// `input` (a path, or a stream's copy) as a command line takes it again:
  /// `-` for stdin's copy, a pipe's path for its copy (for advice such as
  /// "run `evlife process INPUT -o …`").
  static std::string as_argument(const std::string& input);
  std::uint64_t bytes() const noexcept { return bytes_; }

  struct Interrupted {};

 private:
  void copy(const std::string& input, int out, const char* command, bool quiet);
  void remove_copy() noexcept;

  std::string stream_;
  std::string folder_;
  std::string path_;
  std::optional<io::StreamCopyName> name_;  // while the copy exists
  std::uint64_t bytes_ = 0;
};

/// The shared step of every command that reads INPUT: when `input` is a
/// stream, spools it into `spool` and points `input` at the copy. Returns the
/// exit status to end with (input error 3, interrupted 130), or nullopt.
std::optional<int> spool_stream_input(const char* command, std::string& input, bool quiet,
                                      std::optional<InputSpool>& spool);

}  // namespace evlife::cli
