#include "zstd_temp_copy.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zstd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <map>
#include <mutex>
#include <vector>

#include "evlife/io/event_reader.h"
#include "evlife/io/stop.h"
#include "evlife/io/temp_dir.h"
#include "input_file.h"

namespace evlife::io::detail {
namespace {

namespace fs = std::filesystem;

/// The free space a copy leaves at least (a corrupt stream that inflates
/// without end must not fill the disk).
constexpr std::uint64_t kHeadroomBytes = 256ULL << 20;

/// io::temp_dir(); one that is no folder is an error (a silent fall-back
/// would put gigabytes where the user said not to).
std::string checked_temp_dir(const std::string& compressed) {
  const std::string dir = temp_dir();
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw ReadError(compressed, -1, -1,
                    "cannot decompress it: TMPDIR " + dir + " is not a folder (set TMPDIR to one with room)");
  return dir;
}

}  // namespace

std::shared_ptr<const ZstdTempCopy> ZstdTempCopy::of(const std::string& compressed) {
  // Keyed by the file's identity and version: a file rewritten since is a new copy.
  struct stat st {};
  if (::stat(compressed.c_str(), &st) != 0)
    throw ReadError(compressed, -1, -1, std::string("cannot open: ") + std::strerror(errno));
  const std::string key = std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino) + ":" +
                          std::to_string(st.st_size) + ":" + std::to_string(st.st_mtim.tv_sec) + "." +
                          std::to_string(st.st_mtim.tv_nsec);
  static std::mutex mutex;
  static std::map<std::string, std::weak_ptr<const ZstdTempCopy>> copies;
  // Held while inflating: a second opener of the same file waits for the copy
  // instead of making its own.
  const std::lock_guard<std::mutex> lock(mutex);
  std::erase_if(copies, [](const auto& entry) { return entry.second.expired(); });
  if (auto held = copies[key].lock()) return held;
  std::shared_ptr<const ZstdTempCopy> made(new ZstdTempCopy(compressed));
  copies[key] = made;
  return made;
}

ZstdTempCopy::ZstdTempCopy(const std::string& compressed) {
  const std::string dir = checked_temp_dir(compressed);
  std::string name = (fs::path(dir) / "evlife-zstd-XXXXXX.db3").string();
  const int fd = ::mkstemps(name.data(), 4);
  if (fd < 0)
    throw ReadError(compressed, -1, -1,
                    "cannot create its decompressed copy in " + dir + ": " + std::strerror(errno) + " (set TMPDIR)");
  path_ = name;
  try {
    inflate(compressed, fd, dir);
  } catch (...) {
    ::close(fd);
    std::error_code ec;
    fs::remove(path_, ec);
    throw;
  }
  if (::close(fd) != 0) {
    const std::string why = std::strerror(errno);
    std::error_code ec;
    fs::remove(path_, ec);
    throw ReadError(compressed, -1, -1, "cannot write its decompressed copy in " + dir + ": " + why);
  }
}

ZstdTempCopy::~ZstdTempCopy() {
  std::error_code ec;
  // With the files SQLite may add beside a database it opens.
  for (const char* suffix : {"", "-journal", "-wal", "-shm"}) fs::remove(path_ + suffix, ec);
}

void ZstdTempCopy::inflate(const std::string& compressed, int fd, const std::string& dir) {
  const InputFile in(compressed);
  std::error_code ec;
  const fs::space_info space = fs::space(dir, ec);
  const std::uint64_t room = ec || space.available < kHeadroomBytes ? 0 : space.available - kHeadroomBytes;
  std::unique_ptr<ZSTD_DCtx, decltype(&ZSTD_freeDCtx)> ctx(ZSTD_createDCtx(), &ZSTD_freeDCtx);
  std::vector<std::byte> in_buf(ZSTD_DStreamInSize());
  std::vector<std::byte> out_buf(ZSTD_DStreamOutSize());
  std::uint64_t at = 0, written = 0;
  std::size_t last = 1;  // ZSTD_decompressStream's hint: 0 once a frame is complete
  while (at < in.size_bytes()) {
    if (stop_requested())  // seconds for gigabytes: Ctrl-C waited for the whole copy
      throw ReadError(compressed, static_cast<std::int64_t>(at), -1,
                      "stopped while decompressing it (" + std::to_string(written) + " bytes of its copy written, removed)");
    const std::size_t got = in.read_at(at, in_buf);
    if (got == 0) throw ReadError(compressed, static_cast<std::int64_t>(at), -1, "cannot read the file here");
    ZSTD_inBuffer input{in_buf.data(), got, 0};
    while (input.pos < input.size) {
      ZSTD_outBuffer output{out_buf.data(), out_buf.size(), 0};
      const std::uint64_t block_at = at + input.pos;  // where this step's input begins
      last = ZSTD_decompressStream(ctx.get(), &output, &input);
      if (ZSTD_isError(last) != 0U)
        throw ReadError(compressed, static_cast<std::int64_t>(block_at), -1,
                        std::string("corrupt zstd data (") + ZSTD_getErrorName(last) + ")");
      if (written + output.pos > room)
        throw ReadError(compressed, static_cast<std::int64_t>(at + input.pos), -1,
                        "its decompressed copy would leave less than " + std::to_string(kHeadroomBytes >> 20) +
                            " MiB free in " + dir + " (" +
                            std::to_string(written) + " bytes written; set TMPDIR to a folder with room)");
      for (std::size_t done = 0; done < output.pos;) {
        const ssize_t n = ::write(fd, out_buf.data() + done, output.pos - done);
        if (n <= 0)
          throw ReadError(compressed, static_cast<std::int64_t>(at + input.pos), -1,
                          "cannot write its decompressed copy in " + dir + ": " + std::strerror(errno));
        done += static_cast<std::size_t>(n);
      }
      written += output.pos;
    }
    at += got;
  }
  if (last != 0)
    throw ReadError(compressed, static_cast<std::int64_t>(in.size_bytes()), -1,
                    "the zstd stream ends short (file cut?)");
}

}  // namespace evlife::io::detail
