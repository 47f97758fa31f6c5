#include "byte_cursor.h"

#include <algorithm>
#include <cstring>

#include "evlife/io/event_reader.h"

namespace evlife::io::detail {

std::size_t RawCursor::read(std::span<std::byte> out) {
  const std::uint64_t want = std::min<std::uint64_t>(out.size(), end_ - offset_);
  const std::size_t got = file_.read_at(offset_, out.first(static_cast<std::size_t>(want)));
  offset_ += got;
  if (got < out.size()) end_short(offset_ < end_ ? "file truncated" : "the data ends before its stated size");
  return got;
}

std::size_t MemoryCursor::read(std::span<std::byte> out) {
  const std::size_t k = std::min(out.size(), bytes_.size() - pos_);
  std::memcpy(out.data(), bytes_.data() + pos_, k);
  pos_ += k;
  if (k < out.size()) end_short("the data ends before its stated size");
  return k;
}

InflateCursor::InflateCursor(const InputFile& file, std::uint64_t offset, std::uint64_t end, Wrapping wrapping,
                             std::size_t padding_bytes)
    : file_(file), next_(offset), end_(end), padding_bytes_(padding_bytes), input_(kInputBytes) {
  const int window_bits = wrapping == Wrapping::raw ? -MAX_WBITS : MAX_WBITS;
  if (inflateInit2(&z_, window_bits) != Z_OK) throw ReadError(file.path(), -1, -1, "zlib initialisation failed");
}

InflateCursor::InflateCursor(const InflateCursor& other)
    : Cursor(other), file_(other.file_), next_(other.next_), end_(other.end_), padding_bytes_(other.padding_bytes_),
      input_(other.input_), ended_(other.ended_) {
  if (inflateCopy(&z_, const_cast<z_stream*>(&other.z_)) != Z_OK)
    throw ReadError(file_.path(), -1, -1, "zlib state copy failed");
  z_.next_in = reinterpret_cast<Bytef*>(input_.data()) +
               (other.z_.next_in - reinterpret_cast<const Bytef*>(other.input_.data()));
}

InflateCursor::~InflateCursor() { inflateEnd(&z_); }

std::size_t InflateCursor::read(std::span<std::byte> out) {
  // zlib counts in 32 bits: a larger read is done in steps.
  std::size_t done = 0;
  while (done < out.size()) {
    const std::size_t step = std::min<std::size_t>(out.size() - done, std::size_t{1} << 30);
    const std::size_t got = read_step(out.subspan(done, step));
    done += got;
    if (got < step) break;
  }
  return done;
}

std::size_t InflateCursor::read_step(std::span<std::byte> out) {
  z_.next_out = reinterpret_cast<Bytef*>(out.data());
  z_.avail_out = static_cast<uInt>(out.size());
  while (z_.avail_out > 0 && error_.empty()) {
    if (ended_) {
      end_short("the data ends before its stated size");
      break;
    }
    if (z_.avail_in == 0) {
      const std::size_t want = static_cast<std::size_t>(std::min<std::uint64_t>(input_.size(), end_ - next_));
      const std::size_t got = file_.read_at(next_, std::span(input_).first(want));
      next_ += got;
      if (got == 0) {
        error_ = next_ < end_ || end_ > file_.size_bytes() ? "file truncated" : "compressed data ends early";
        break;
      }
      z_.next_in = reinterpret_cast<Bytef*>(input_.data());
      z_.avail_in = static_cast<uInt>(got);
    }
    const int rc = inflate(&z_, Z_NO_FLUSH);
    if (rc == Z_STREAM_END) {
      ended_ = true;
    } else if (rc != Z_OK && rc != Z_BUF_ERROR) {
      error_ = std::string("corrupt compressed data (zlib: ") + (z_.msg ? z_.msg : "error") + ")";
    }
  }
  return out.size() - z_.avail_out;
}

bool InflateCursor::finish() {
  // Up to padding_bytes_ may follow the data inside the stream; then its end (checksum checked by zlib).
  std::byte scratch[16];
  const std::size_t allowed = std::min(padding_bytes_, sizeof scratch - 1);
  const std::size_t extra = read(std::span(scratch).first(allowed + 1));
  if (extra > allowed && error_.empty()) error_ = "the data is longer than its stated size";
  if (ended_short_) {  // = reached the stream's end
    error_.clear();
    ended_short_ = false;
  }
  return ended_ && error_.empty();
}

bool InflateCursor::skip(std::uint64_t n) {
  std::vector<std::byte> scratch(kInputBytes);
  while (n > 0) {
    const std::size_t step = static_cast<std::size_t>(std::min<std::uint64_t>(n, scratch.size()));
    if (read(std::span(scratch).first(step)) != step) return false;
    n -= step;
  }
  return true;
}

}  // namespace evlife::io::detail
