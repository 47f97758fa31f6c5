// A read-only file seen through one fixed buffer: the binary readers decode
// straight from it (no per-event calls into stdio), memory stays constant.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "evlife/io/uninitialized_array.h"

namespace evlife::io {

class ChunkedFile {
 public:
  /// Opens `path`; throws ReadError if it cannot be opened.
  explicit ChunkedFile(const std::string& path, std::size_t capacity_bytes = std::size_t{1} << 20);
  ~ChunkedFile();
  ChunkedFile(const ChunkedFile&) = delete;
  ChunkedFile& operator=(const ChunkedFile&) = delete;

  const std::string& path() const noexcept { return path_; }
  std::int64_t size_bytes() const noexcept { return size_bytes_; }

  /// Buffered bytes from the current position on.
  const std::uint8_t* data() const noexcept { return buffer_.data() + pos_; }
  std::size_t available() const noexcept { return end_ - pos_; }
  /// File offset of data()[0].
  std::int64_t offset() const noexcept {
    return buffer_offset_ + static_cast<std::int64_t>(pos_);
  }
  void consume(std::size_t n) noexcept { pos_ += n; }

  /// Makes at least `min_bytes` (<= capacity) available unless the file ends
  /// first; returns available(). Throws ReadError on an I/O error.
  std::size_t fill(std::size_t min_bytes);

  /// Copies the next `n` bytes (any size) to `dst`; returns how many there were.
  std::size_t read(void* dst, std::size_t n);

  /// Moves to an absolute offset (drops the buffer).
  void seek(std::int64_t offset);

 private:
  std::string path_;
  std::FILE* file_ = nullptr;
  UninitializedArray<std::uint8_t> buffer_;  // bytes [pos_, end_) hold the file
  std::size_t pos_ = 0;
  std::size_t end_ = 0;
  std::int64_t buffer_offset_ = 0;
  std::int64_t size_bytes_ = 0;
};

}  // namespace evlife::io
