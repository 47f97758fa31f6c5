#include "evlife/io/temp_dir.h"

#include <cstdlib>

namespace evlife::io {

std::string temp_dir() {
  const char* env = std::getenv("TMPDIR");
  return env != nullptr && *env != '\0' ? env : "/tmp";
}

}  // namespace evlife::io
