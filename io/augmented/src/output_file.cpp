#include "output_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "evlife/io/output_path.h"
#include "evlife/io/write_error.h"

namespace evlife::io::detail {

OutputFile::OutputFile(const std::string& path) : path_(path), buffer_(kBufferBytes) {
  const std::string folder_problem = create_output_folders(path);
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    const int err = errno;
    throw WriteError(path, folder_problem.empty() ? std::string("cannot create: ") + std::strerror(err) : folder_problem,
                     err);
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
  while (bytes > 0) {
    const ssize_t n = ::write(fd_, data, bytes);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      throw WriteError(path_, std::string("write failed: ") + std::strerror(err), err);
    }
    data += n;
    bytes -= static_cast<std::size_t>(n);
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
