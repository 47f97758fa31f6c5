#include "evlife/io/write_error.h"

namespace evlife::io {

WriteError::WriteError(const std::string& path, const std::string& what, int os_error)
    : std::runtime_error(path + ": " + what), path_(path), os_error_(os_error) {}

}  // namespace evlife::io
