#include "evlife/io/write_error.h"

namespace evlife::io {

WriteError::WriteError(const std::string& path, const std::string& what, int os_error,
                       std::optional<std::uint64_t> records_in_file)
    : std::runtime_error(path + ": " + what), path_(path), os_error_(os_error), records_in_file_(records_in_file) {}

}  // namespace evlife::io
