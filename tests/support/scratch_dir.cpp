#include "scratch_dir.h"

#include <unistd.h>

#include <fstream>

namespace evlife::test {

ScratchDir::ScratchDir(const std::string& name)
    : dir_(std::filesystem::temp_directory_path() / ("evlife_" + name + "_" + std::to_string(::getpid()))) {
  std::filesystem::remove_all(dir_);
  std::filesystem::create_directories(dir_);
}

ScratchDir::~ScratchDir() {
  std::error_code ec;
  std::filesystem::remove_all(dir_, ec);
}

std::string ScratchDir::save(const std::string& name, std::string_view bytes) const {
  const std::string p = (dir_ / name).string();
  std::ofstream(p, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return p;
}

}  // namespace evlife::test
