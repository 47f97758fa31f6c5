// A temporary folder of one test process (removed with the object), where a
// test writes the files it then reads.
#pragma once

#include <filesystem>
#include <string>
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
  std::string save(const std::string& name, const std::vector<char>& bytes) const;

 private:
  std::filesystem::path dir_;
};

}  // namespace evlife::test
