// Private: a read-only file with positioned reads (pread), so that several
// cursors (e.g. one per .mat column) share one descriptor. Errors become
// ReadError naming the file.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

namespace evlife::io::detail {

class InputFile {
 public:
  /// Throws ReadError("cannot open: <reason>") for a missing/unreadable file
  /// or a directory.
  explicit InputFile(const std::string& path);
  ~InputFile();
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;

  /// Reads up to out.size() bytes at `offset`; fewer only at end of file.
  /// Throws ReadError on an I/O error.
  std::size_t read_at(std::uint64_t offset, std::span<std::byte> out) const;

  std::uint64_t size_bytes() const noexcept { return size_bytes_; }
  const std::string& path() const noexcept { return path_; }

 private:
  std::string path_;
  int fd_ = -1;
  std::uint64_t size_bytes_ = 0;
};

}  // namespace evlife::io::detail
