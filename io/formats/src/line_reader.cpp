#include "line_reader.h"

#include <span>

namespace evlife::io::detail {

LineReader::LineReader(const std::string& path) : file_(path), buffer_(kBufferBytes) {
  refill();
  if (buffered().starts_with(kUtf8ByteOrderMark)) {
    pos_ += kUtf8ByteOrderMark.size();
    offset_ += kUtf8ByteOrderMark.size();
  }
}

std::string LineReader::too_long_note() {
  return "(line longer than " + std::to_string(kBufferBytes) + " bytes)";
}

LineReader::Next LineReader::refill() {
  const std::size_t leftover = end_ - pos_;
  if (leftover == buffer_.size()) return Next::too_long;
  std::memmove(buffer_.data(), buffer_.data() + pos_, leftover);
  pos_ = 0;
  end_ = leftover;
  const std::size_t got =
      file_.read_at(file_pos_, std::as_writable_bytes(buffer_.span()).subspan(leftover));
  file_pos_ += got;
  end_ += got;
  at_end_ = end_ < buffer_.size();
  return got > 0 ? Next::line : Next::end_of_file;
}

}  // namespace evlife::io::detail
