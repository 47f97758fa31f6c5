#include "chunked_file.h"

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "evlife/io/event_reader.h"

namespace evlife::io {

ChunkedFile::ChunkedFile(const std::string& path, std::size_t capacity_bytes)
    : path_(path), buffer_(capacity_bytes) {
  file_ = std::fopen(path.c_str(), "rb");
  if (file_ == nullptr) {
    throw ReadError(path, -1, -1, std::string("cannot open: ") + std::strerror(errno));
  }
  std::setvbuf(file_, nullptr, _IONBF, 0);  // we buffer ourselves
  if (std::fseek(file_, 0, SEEK_END) == 0) {
    size_bytes_ = std::ftell(file_);
    std::fseek(file_, 0, SEEK_SET);
  }
}

ChunkedFile::~ChunkedFile() {
  if (file_ != nullptr) std::fclose(file_);
}

std::size_t ChunkedFile::fill(std::size_t min_bytes) {
  if (available() >= min_bytes) return available();
  const std::size_t left = available();
  std::memmove(buffer_.data(), buffer_.data() + pos_, left);
  buffer_offset_ += static_cast<std::int64_t>(pos_);
  pos_ = 0;
  end_ = left;
  while (end_ < min_bytes) {
    const std::size_t got = std::fread(buffer_.data() + end_, 1, buffer_.size() - end_, file_);
    if (got == 0) {
      if (std::ferror(file_) != 0) {
        throw ReadError(path_, offset() + static_cast<std::int64_t>(end_), -1,
                        "I/O error while reading");
      }
      break;  // end of file
    }
    end_ += got;
  }
  return available();
}

std::size_t ChunkedFile::read(void* dst, std::size_t n) {
  auto* out = static_cast<std::uint8_t*>(dst);
  std::size_t done = std::min(n, available());
  std::memcpy(out, data(), done);
  consume(done);
  while (done < n) {
    // Large reads bypass the buffer; the buffer restarts after them.
    const std::size_t got = std::fread(out + done, 1, n - done, file_);
    buffer_offset_ += static_cast<std::int64_t>(pos_ + got);
    pos_ = end_ = 0;
    done += got;
    if (got == 0) {
      if (std::ferror(file_) != 0) throw ReadError(path_, offset(), -1, "I/O error while reading");
      break;
    }
  }
  return done;
}

void ChunkedFile::seek(std::int64_t offset) {
  if (std::fseek(file_, offset, SEEK_SET) != 0) {
    throw ReadError(path_, offset, -1, "cannot seek");
  }
  buffer_offset_ = offset;
  pos_ = end_ = 0;
}

}  // namespace evlife::io
