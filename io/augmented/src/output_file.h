// Private: a buffered output file whose failures (open, write, close; e.g.
// ENOSPC on /dev/full) become WriteError naming the file.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace evlife::io::detail {

/// The records a file is made of, so that a failed write (a full disk) cuts
/// it back to its last whole one: a reader then takes every record written,
/// not stop at a cut one, and the error says how many the file holds.
/// `record_bytes` 0: lines (text), after `header_lines` that are no record;
/// else records of that size after a header of `header_bytes`.
struct OutputRecords {
  std::size_t header_bytes = 0;
  std::size_t record_bytes = 0;
  std::size_t header_lines = 0;
};

class OutputFile {
 public:
  static constexpr std::size_t kBufferBytes = 1 << 20;

  /// Creates/truncates `path`; throws WriteError.
  explicit OutputFile(const std::string& path, OutputRecords records = {});
  /// Closes without reporting errors (use close() to learn about them).
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  /// Space to format into: at least `bytes` (≤ kBufferBytes) writable chars
  /// at the returned pointer; commit(n) makes n of them part of the file.
  char* reserve(std::size_t bytes) {
    if (kBufferBytes - used_ < bytes) flush();
    return buffer_.data() + used_;
  }
  void commit(std::size_t bytes) noexcept { used_ += bytes; }
  void append(const void* data, std::size_t bytes);

  void flush();  ///< throws WriteError
  void close();  ///< flush + close; throws WriteError; idempotent
  bool is_open() const noexcept { return fd_ >= 0; }
  const std::string& path() const noexcept { return path_; }

 private:
  void write_all(const char* data, std::size_t bytes);
  // After a failed write of `written` of the bytes at `data`: the file cut
  // back to its last whole record; a note for the error saying so and how
  // many whole records it holds (`records`; none for a FIFO).
  std::string keep_whole_records(const char* data, std::size_t written, std::optional<std::uint64_t>& records);
  // A FIFO without room: waits for it, or throws WriteError on a stop (stop.h).
  void wait_for_reader(std::size_t bytes_left);
  std::string path_;
  int fd_ = -1;
  bool waits_for_reader_ = false;  // a FIFO, written without blocking
  std::vector<char> buffer_;
  std::size_t used_ = 0;
  OutputRecords records_;
  std::uint64_t file_bytes_ = 0;  // written so far
  std::uint64_t file_lines_ = 0;  // newlines written so far (text files only)
};

}  // namespace evlife::io::detail
