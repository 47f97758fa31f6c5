#include "evlife/io/installed_file.h"

#include <filesystem>
#include <system_error>

namespace evlife::io {

std::string beside_executable(const std::string& relative) {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec || relative.empty()) return {};
  return (exe.parent_path() / relative).lexically_normal().string();
}

std::string installed_file(const std::string& relative) {
  std::string candidate = beside_executable(relative);
  std::error_code ec;
  return !candidate.empty() && std::filesystem::is_regular_file(candidate, ec) ? candidate : std::string{};
}

}  // namespace evlife::io
