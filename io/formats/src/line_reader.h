// Private: a text file read line by line through one fixed buffer, which is
// also the longest line accepted (the text readers: CSV, RPG text, augmented
// CSV). No allocation after construction.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "evlife/io/event_reader.h"  // SkippedKindCount
#include "evlife/io/uninitialized_array.h"
#include "input_file.h"

namespace evlife::io::detail {

/// Comment lines after a text file's first event (CSV, RPG text): an event
/// whose first byte was damaged into '#' reads as one, so they are counted
/// and shown as skipped records, never dropped unsaid.
struct CommentsAmongEvents {
  std::uint64_t count = 0;
  std::vector<SkippedKindCount> kinds() const {
    if (count == 0) return {};
    return {{"comment-line-among-the-events", count}};
  }
};

/// A UTF-8 byte-order mark, which Excel's "CSV UTF-8", PowerShell and
/// Notepad write before the first line: not part of that line.
inline constexpr std::string_view kUtf8ByteOrderMark = "\xEF\xBB\xBF";

/// `head` without a leading byte-order mark (for the sniffers, which see raw bytes).
inline std::string_view without_byte_order_mark(std::string_view head) noexcept {
  return head.starts_with(kUtf8ByteOrderMark) ? head.substr(kUtf8ByteOrderMark.size()) : head;
}

class LineReader {
 public:
  static constexpr std::size_t kBufferBytes = 1 << 20;

  enum class Next { line, end_of_file, too_long };

  /// Opens `path` (InputFile's errors) and reads the first buffer, past a
  /// byte-order mark (offsets stay the file's).
  explicit LineReader(const std::string& path);

  /// The next line without its '\n' (the last line may lack one), valid
  /// until the next call; consume() moves past it. too_long: no '\n' within
  /// kBufferBytes from offset().
  Next peek(std::string_view& line) {
    for (;;) {
      const char* begin = buffer_.data() + pos_;
      const std::size_t available = end_ - pos_;
      if (const void* nl = std::memchr(begin, '\n', available)) {
        const auto bytes = static_cast<std::size_t>(static_cast<const char*>(nl) - begin);
        line = std::string_view(begin, bytes);
        line_bytes_ = bytes + 1;
        unterminated_ = false;
        return Next::line;
      }
      const Next more = refill();
      if (more == Next::line) continue;
      if (more == Next::too_long || pos_ == end_) return more;
      line = std::string_view(buffer_.data() + pos_, end_ - pos_);  // last line without '\n'
      line_bytes_ = end_ - pos_;
      unterminated_ = true;
      return Next::line;
    }
  }
  /// The line peek() returned is the file's last and has no '\n': for a
  /// format whose writer ends every line, a file cut short.
  bool peeked_unterminated() const noexcept { return unterminated_; }
  /// Moves past the line peek() returned, with its '\n'.
  void consume() noexcept {
    pos_ += line_bytes_;
    offset_ += line_bytes_;
    line_bytes_ = 0;
  }

  /// The bytes read and not consumed yet (after construction: the file's head).
  std::string_view buffered() const noexcept { return {buffer_.data() + pos_, end_ - pos_}; }
  /// buffered() runs to the end of the file: its last line is whole even without '\n'.
  bool buffered_to_end() const noexcept { return at_end_; }
  /// File offset of the next line (the bytes consumed).
  std::uint64_t offset() const noexcept { return offset_; }
  const std::string& path() const noexcept { return file_.path(); }
  /// "(line longer than <kBufferBytes> bytes)", for the readers' error messages.
  static std::string too_long_note();

 private:
  /// Keeps the unconsumed tail, reads more after it: line when it got bytes,
  /// end_of_file when none, too_long when the tail fills the buffer.
  Next refill();

  InputFile file_;
  UninitializedArray<char> buffer_;  // bytes [pos_, end_) hold the file, the rest nothing yet
  std::size_t pos_ = 0, end_ = 0;  // unconsumed bytes: buffer_[pos_, end_)
  std::size_t line_bytes_ = 0;     // what consume() moves past
  bool unterminated_ = false;      // the peeked line ends the file without '\n'
  bool at_end_ = false;            // the last read stopped short: buffer_[end_] is the file's end
  std::uint64_t file_pos_ = 0;     // file offset of buffer_[end_]
  std::uint64_t offset_ = 0;       // file offset of buffer_[pos_]
};

}  // namespace evlife::io::detail
