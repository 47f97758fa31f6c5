#include "evlife/io/installed_file.h"

#include <filesystem>
#include <system_error>

namespace evlife::io {

std::string installed_file(const std::string& relative) {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec || relative.empty()) return {};
  const std::filesystem::path candidate = (exe.parent_path() / relative).lexically_normal();
  return std::filesystem::is_regular_file(candidate, ec) ? candidate.string() : std::string{};
}

}  // namespace evlife::io
