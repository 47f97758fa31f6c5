#include "input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "evlife/io/event_reader.h"

namespace evlife::io::detail {

InputFile::InputFile(const std::string& path) : path_(path) {
  // O_NONBLOCK: a pipe with no writer yet is refused below, not waited on
  // forever (no effect on the reads of regular files).
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd_ < 0) throw ReadError(path, -1, -1, std::string("cannot open: ") + std::strerror(errno));
  struct stat st {};
  if (::fstat(fd_, &st) != 0) {
    const int err = errno;
    ::close(fd_);
    throw ReadError(path, -1, -1, std::string("cannot stat: ") + std::strerror(err));
  }
  if (S_ISDIR(st.st_mode)) {
    ::close(fd_);
    throw ReadError(path, -1, -1, "cannot open: is a directory");
  }
  if (S_ISFIFO(st.st_mode) || S_ISSOCK(st.st_mode)) {
    ::close(fd_);
    throw ReadError(path, -1, -1,
                    "a pipe: the readers read files (they read the start again once they know the format); save "
                    "the stream to a file first (the evlife command line does that itself for pipes and `-`)");
  }
  size_bytes_ = static_cast<std::uint64_t>(st.st_size);
#ifdef POSIX_FADV_SEQUENTIAL
  ::posix_fadvise(fd_, 0, 0, POSIX_FADV_SEQUENTIAL);
#endif
}

InputFile::~InputFile() {
  if (fd_ >= 0) ::close(fd_);
}

std::size_t InputFile::read_at(std::uint64_t offset, std::span<std::byte> out) const {
  std::size_t done = 0;
  while (done < out.size()) {
    const ssize_t got = ::pread(fd_, out.data() + done, out.size() - done,
                                static_cast<off_t>(offset + done));
    if (got < 0) {
      if (errno == EINTR) continue;
      throw ReadError(path_, static_cast<std::int64_t>(offset + done), -1,
                      std::string("read failed: ") + std::strerror(errno));
    }
    if (got == 0) break;  // end of file
    done += static_cast<std::size_t>(got);
  }
  return done;
}

}  // namespace evlife::io::detail
