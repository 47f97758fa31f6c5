// Failure to write an output file (disk full, permission, ...).
#pragma once

#include <stdexcept>
#include <string>

namespace evlife::io {

/// Names the file; what() says what failed.
class WriteError : public std::runtime_error {
 public:
  /// `os_error`: the errno of the failed system call, 0 when none (Python's
  /// OSError.errno: ENOSPC for a full disk, ENOTDIR, EACCES, ...).
  WriteError(const std::string& path, const std::string& what, int os_error = 0);
  const std::string& path() const noexcept { return path_; }
  int os_error() const noexcept { return os_error_; }

 private:
  std::string path_;
  int os_error_ = 0;
};

}  // namespace evlife::io
