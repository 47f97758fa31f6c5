#include "evlife/io/write_error.h"

namespace evlife::io {

WriteError::WriteError(const std::string& path, const std::string& what)
    : std::runtime_error(path + ": " + what), path_(path) {}

}  // namespace evlife::io
