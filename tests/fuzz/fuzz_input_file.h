// Readers take a path, so each fuzz input is written to a file first: on
// /dev/shm (tmpfs, no disk I/O), one file per process, with the extension
// that makes open_event_reader pick the format under test when the content
// does not say (formats with magic bytes are sniffed from the content).
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace evlife::fuzz {

/// Writes `data` to this process's scratch file ending in `extension` and
/// returns its path. Aborts (a finding for libFuzzer, not for the code under
/// test) if the scratch file cannot be written.
inline const std::string& write_input_file(const std::uint8_t* data, std::size_t size,
                                           const char* extension) {
  static const std::string path = [extension] {
    const char* dir = std::getenv("EVLIFE_FUZZ_TMPDIR");
    std::string d = dir != nullptr ? dir : (access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp");
    return d + "/evlife_fuzz_" + std::to_string(getpid()) + extension;
  }();
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr || (size > 0 && std::fwrite(data, 1, size, f) != size) || std::fclose(f) != 0) {
    std::perror(path.c_str());
    std::abort();
  }
  return path;
}

/// Deletes the scratch file at exit (libFuzzer exits via exit()).
inline void remove_input_file_at_exit(const std::string& path) {
  static const std::string* p = &path;
  std::atexit([] { std::remove(p->c_str()); });
}

}  // namespace evlife::fuzz
