// Private: a zstd-compressed file (one or more frames) decompressed into a
// temporary file, for a library that needs a file (SQLite, for a
// file-compressed rosbag2 bag's NAME.db3.zstd). One copy per file per
// process, shared by the readers open on it at once (a command's probe and
// its reader), removed when the last one lets it go.
#pragma once

#include <memory>
#include <string>

namespace evlife::io::detail {

class ZstdTempCopy {
 public:
  /// The copy of `compressed`, made in TMPDIR (/tmp when unset) unless a
  /// reader holds one already. Throws ReadError naming `compressed` (and the
  /// byte offset of a corrupt or cut stream): also where TMPDIR is not a
  /// folder, or where the copy would leave too little free space there
  /// (kHeadroomBytes, zstd_temp_copy.cpp).
  static std::shared_ptr<const ZstdTempCopy> of(const std::string& compressed);

  ~ZstdTempCopy();
  ZstdTempCopy(const ZstdTempCopy&) = delete;
  ZstdTempCopy& operator=(const ZstdTempCopy&) = delete;
  /// The decompressed copy's path.
  const std::string& path() const noexcept { return path_; }

 private:
  explicit ZstdTempCopy(const std::string& compressed);
  void inflate(const std::string& compressed, int fd, const std::string& dir);

  std::string path_;
};

}  // namespace evlife::io::detail
