#include "output_file.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "evlife/io/output_path.h"
#include "evlife/io/write_error.h"
#include "evlife/io/stop.h"

namespace evlife::io::detail {

namespace {

// open() of a FIFO for writing blocks until a reader opens it, deaf to a
// stop (SA_RESTART restarts it): a FIFO is opened without blocking, in steps
// of 100 ms while it has no reader, until a stop (stop.h) ends the wait with
// a WriteError. Else a plain open(); -1 and errno on failure.
int open_output(const std::string& path) {
  constexpr int kStepMs = 100;  // how soon a stop is noticed
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0 || !S_ISFIFO(st.st_mode)) {
    return ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  }
  for (;;) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd >= 0 || (errno != ENXIO && errno != EINTR)) return fd;  // ENXIO: no reader yet
    if (stop_requested()) throw WriteError(path, "stopped while no reader had opened this FIFO (nothing written)");
    ::poll(nullptr, 0, kStepMs);
  }
}

}  // namespace

OutputFile::OutputFile(const std::string& path, OutputRecords records)
    : path_(path), buffer_(kBufferBytes), records_(records) {
  const std::string folder_problem = create_output_folders(path);
  fd_ = open_output(path);
  if (fd_ < 0) {
    const int err = errno;
    throw WriteError(path, folder_problem.empty() ? std::string("cannot create: ") + std::strerror(err) : folder_problem,
                     err);
  }
  // A FIFO's writes must not block past a stop (stop.h). This open
  // file description is ours alone (open() of a FIFO makes a new one).
  struct stat st {};
  if (::fstat(fd_, &st) == 0 && S_ISFIFO(st.st_mode)) {
    const int flags = ::fcntl(fd_, F_GETFL);
    waits_for_reader_ = flags >= 0 && ::fcntl(fd_, F_SETFL, flags | O_NONBLOCK) == 0;
  }
}

OutputFile::~OutputFile() {
  if (fd_ < 0) return;
  try {
    flush();
  } catch (...) {  // a destructor never throws; close() reports
  }
  if (fd_ >= 0) ::close(fd_);
}

void OutputFile::append(const void* data, std::size_t bytes) {
  const char* p = static_cast<const char*>(data);
  while (bytes > 0) {
    if (used_ == kBufferBytes) flush();
    const std::size_t k = std::min(bytes, kBufferBytes - used_);
    std::memcpy(buffer_.data() + used_, p, k);
    used_ += k;
    p += k;
    bytes -= k;
  }
}

void OutputFile::write_all(const char* data, std::size_t bytes) {
  if (fd_ < 0) throw WriteError(path_, "write after close");
  const char* const start = data;
  while (bytes > 0) {
    const ssize_t n = ::write(fd_, data, bytes);
    if (n < 0) {
      if (errno == EINTR) continue;
      if (waits_for_reader_ && (errno == EAGAIN || errno == EWOULDBLOCK)) {
        wait_for_reader(bytes);
        continue;
      }
      const int err = errno;
      std::optional<std::uint64_t> records;
      const std::string note = keep_whole_records(start, static_cast<std::size_t>(data - start), records);
      throw WriteError(path_, std::string("write failed: ") + std::strerror(err) + note, err, records);
    }
    if (records_.record_bytes == 0) file_lines_ += static_cast<std::uint64_t>(std::count(data, data + n, '\n'));
    data += n;
    bytes -= static_cast<std::size_t>(n);
    file_bytes_ += static_cast<std::uint64_t>(n);
  }
}

std::string OutputFile::keep_whole_records(const char* data, std::size_t written,
                                           std::optional<std::uint64_t>& records_kept) {
  if (waits_for_reader_) return {};  // a FIFO's reader took what it took
  std::uint64_t keep = file_bytes_;
  std::uint64_t records = 0;
  if (records_.record_bytes == 0) {  // lines: up to the last newline written
    std::size_t i = written;
    while (i > 0 && data[i - 1] != '\n') --i;
    keep = file_bytes_ - written + i;
    if (i == 0) {  // none in this write: the file ended on a line before it (writes start at one)
      keep = file_bytes_ - written;
    }
    // What is cut holds no newline: every line counted stays.
    records = file_lines_ > records_.header_lines ? file_lines_ - records_.header_lines : 0;
  } else if (file_bytes_ > records_.header_bytes) {
    records = (file_bytes_ - records_.header_bytes) / records_.record_bytes;
    keep = records_.header_bytes + records * records_.record_bytes;
  }
  records_kept = records;
  const std::string held = std::to_string(records) + (records == 1 ? " record" : " records");
  if (keep == file_bytes_) return " (the file holds " + held + ", whole)";
  if (::ftruncate(fd_, static_cast<off_t>(keep)) != 0) return " (a record is cut at the file's end, after " + held + ")";
  file_bytes_ = keep;
  return " (the file ends after its last whole record: " + held + " in it)";
}

void OutputFile::wait_for_reader(std::size_t bytes_left) {
  constexpr int kStepMs = 100;  // how soon a stop is noticed
  for (;;) {
    pollfd room{fd_, POLLOUT, 0};
    const int ready = ::poll(&room, 1, kStepMs);
    if (ready > 0 || (ready < 0 && errno != EINTR)) return;  // room, a closed reader or an error: write() says
    if (stop_requested()) {
      throw WriteError(path_, "stopped while the reader of this FIFO took no data (" + std::to_string(bytes_left) +
                                  " bytes not written)");
    }
  }
}

void OutputFile::flush() {
  const std::size_t n = used_;
  used_ = 0;  // dropped on failure: the error is reported, never retried
  write_all(buffer_.data(), n);
}

void OutputFile::close() {
  if (fd_ < 0) return;
  try {
    flush();
  } catch (...) {
    ::close(fd_);
    fd_ = -1;
    throw;
  }
  const int rc = ::close(fd_);
  fd_ = -1;
  if (rc != 0) {
    const int err = errno;
    throw WriteError(path_, std::string("close failed: ") + std::strerror(err), err);
  }
}

}  // namespace evlife::io::detail
