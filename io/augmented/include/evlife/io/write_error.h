// Failure to write an output file (disk full, permission, ...).
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>

namespace evlife::io {

/// Names the file; what() says what failed.
class WriteError : public std::runtime_error {
 public:
  /// `os_error`: the errno of the failed system call, 0 when none (Python's
  /// OSError.errno: ENOSPC for a full disk, ENOTDIR, EACCES, ...).
  /// `records_in_file`: how many whole records the file holds after the
  /// failure, where the writer knows (its text or fixed-size records).
  WriteError(const std::string& path, const std::string& what, int os_error = 0,
             std::optional<std::uint64_t> records_in_file = std::nullopt);
  const std::string& path() const noexcept { return path_; }
  int os_error() const noexcept { return os_error_; }
  std::optional<std::uint64_t> records_in_file() const noexcept { return records_in_file_; }

 private:
  std::string path_;
  int os_error_ = 0;
  std::optional<std::uint64_t> records_in_file_;
};

}  // namespace evlife::io
