// Failure to write an output file (disk full, permission, ...).
#pragma once

#include <stdexcept>
#include <string>

namespace evlife::io {

/// Names the file; what() says what failed.
class WriteError : public std::runtime_error {
 public:
  WriteError(const std::string& path, const std::string& what);
  const std::string& path() const noexcept { return path_; }

 private:
  std::string path_;
};

}  // namespace evlife::io
