// Private: sequential byte sources over part of a file, for readers that
// decode values from one or several places of a file at once (a MATLAB
// matrix's columns, a ZIP archive's arrays): raw bytes, bytes in memory, or a
// deflate stream (zlib-wrapped as MATLAB writes it, or raw as ZIP members
// hold it). A fault (corrupt or truncated data) is reported through error()
// instead of thrown, so that the values read before it can be delivered.
#pragma once

#include <zlib.h>

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "input_file.h"

namespace evlife::io::detail {

class Cursor {
 public:
  virtual ~Cursor() = default;
  /// Fills `out` fully unless the data ends or is corrupt; returns bytes read.
  virtual std::size_t read(std::span<std::byte> out) = 0;
  /// Called after the last value: checks what follows (for deflate data, the
  /// stream's end and checksum). False on failure (see error()).
  virtual bool finish() { return error_.empty(); }
  const std::string& error() const { return error_; }
  /// The data ended before a read was filled (error() says so).
  bool ended_short() const { return ended_short_; }

 protected:
  void end_short(const char* why) {
    if (!error_.empty()) return;
    error_ = why;
    ended_short_ = true;
  }
  std::string error_;
  bool ended_short_ = false;
};

/// The file's bytes [offset, end).
class RawCursor final : public Cursor {
 public:
  RawCursor(const InputFile& file, std::uint64_t offset, std::uint64_t end)
      : file_(file), offset_(offset), end_(end) {}
  std::size_t read(std::span<std::byte> out) override;
  std::uint64_t offset() const { return offset_; }

 private:
  const InputFile& file_;
  std::uint64_t offset_, end_;
};

class MemoryCursor final : public Cursor {
 public:
  explicit MemoryCursor(std::vector<std::byte> bytes) : bytes_(std::move(bytes)) {}
  std::size_t read(std::span<std::byte> out) override;

 private:
  std::vector<std::byte> bytes_;
  std::size_t pos_ = 0;
};

/// The deflate stream in the file's bytes [offset, end), decompressed.
class InflateCursor final : public Cursor {
 public:
  enum class Wrapping {
    zlib,  ///< RFC 1950 header and Adler-32 (MATLAB's miCOMPRESSED)
    raw,   ///< RFC 1951 alone (a ZIP member; its CRC-32 is the archive's)
  };
  /// finish() accepts up to `padding_bytes` after the data (MATLAB pads an
  /// element to 8 bytes inside the stream).
  InflateCursor(const InputFile& file, std::uint64_t offset, std::uint64_t end, Wrapping wrapping,
                std::size_t padding_bytes = 0);
  InflateCursor(const InflateCursor& other);
  InflateCursor& operator=(const InflateCursor&) = delete;
  ~InflateCursor() override;
  std::size_t read(std::span<std::byte> out) override;
  bool finish() override;
  /// Discards `n` bytes; false on failure (see error()).
  bool skip(std::uint64_t n);

 private:
  static constexpr std::size_t kInputBytes = 1 << 16;
  std::size_t read_step(std::span<std::byte> out);  // at most 2^30 bytes

  const InputFile& file_;
  std::uint64_t next_, end_;  // compressed bytes not yet fed to zlib
  std::size_t padding_bytes_;
  std::vector<std::byte> input_;
  z_stream z_{};
  bool ended_ = false;
};

}  // namespace evlife::io::detail
