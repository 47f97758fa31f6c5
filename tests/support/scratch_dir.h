// A temporary folder of one test process (removed with the object), where a
// test writes the files it then reads.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace evlife::test {

class ScratchDir {
 public:
  /// <tmp>/evlife_<name>_<pid>, created empty.
  explicit ScratchDir(const std::string& name);
  ~ScratchDir();
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  const std::filesystem::path& path() const { return dir_; }
  /// The path of the file `name` in the folder (not created).
  std::string file(const std::string& name) const { return (dir_ / name).string(); }
  /// Writes `bytes` to the file `name` in the folder; returns its path.
  std::string save(const std::string& name, std::string_view bytes) const;
  std::string save(const std::string& name, const std::vector<char>& bytes) const {
    return save(name, std::string_view(bytes.data(), bytes.size()));
  }
  std::string save(const std::string& name, const std::vector<std::uint8_t>& bytes) const {
    return save(name, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  }

 private:
  std::filesystem::path dir_;
};

}  // namespace evlife::test
