#include "evlife/render/media.h"

#include <dlfcn.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "evlife/io/installed_file.h"
#include "media_backend.h"

namespace evlife::render {
namespace {

// The plugin: $EVLIFE_MEDIA_PLUGIN when set, else an installed tool's own
// (relative to the executable: whatever prefix it was installed to), else the
// build tree's (when this build tree still exists), else where the configured
// prefix would put it, else the loader's search path.
detail::MediaBackend& backend() {
  static std::once_flag once;
  static detail::MediaBackend* loaded = nullptr;
  static std::string failure;
  std::call_once(once, [] {
    std::string tried;
    // EVLIFE_MEDIA_PLUGIN: an explicit path (a relocated install; tests).
    const char* user = std::getenv("EVLIFE_MEDIA_PLUGIN");
    std::vector<std::string> candidates;
    if (user != nullptr && *user != '\0') {
      candidates = {user};
    } else {
      // Listed when absent too: an installed tool's error then names where its plugin belongs.
      if (std::string own = io::beside_executable(EVLIFE_MEDIA_INSTALLED_REL); !own.empty()) {
        candidates.push_back(std::move(own));
      }
      candidates.insert(candidates.end(), {EVLIFE_MEDIA_BUILD_PATH, EVLIFE_MEDIA_INSTALL_PATH, "libevlife_media.so"});
    }
    for (const std::string& path : candidates) {
      const char* candidate = path.c_str();
      std::error_code ec;
      const bool absolute = candidate[0] == '/';
      if (absolute && !std::filesystem::exists(candidate, ec)) {
        tried += std::string("\n  ") + candidate + ": no such file";
        continue;
      }
      void* handle = dlopen(candidate, RTLD_NOW | RTLD_LOCAL);
      if (handle == nullptr) {
        const char* why = dlerror();
        tried += std::string("\n  ") + candidate + ": " + (why ? why : "?");
        continue;
      }
      auto* entry = reinterpret_cast<detail::MediaBackend* (*)()>(dlsym(handle, EVLIFE_MEDIA_ENTRY_POINT));
      if (entry == nullptr) {
        tried += std::string("\n  ") + candidate + ": no " EVLIFE_MEDIA_ENTRY_POINT;
        continue;
      }
      loaded = entry();
      return;
    }
    failure = "cannot load libevlife_media.so (image, video and window support)" +
              (tried.empty() ? std::string(": not found") : tried);
  });
  if (loaded == nullptr) throw std::runtime_error(failure);
  return *loaded;
}

// The whole file, every write and the close checked (a full disk shows at
// either); a file cut short is removed, not left to read as an image.
// "" on success, else why not.
std::string write_whole_file(const std::string& path, const std::vector<unsigned char>& bytes) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return std::strerror(errno);
  int err = 0;
  for (std::size_t done = 0; done < bytes.size() && err == 0;) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n > 0) done += static_cast<std::size_t>(n);
    else if (n == 0) err = EIO;
    else if (errno != EINTR) err = errno;
  }
  struct stat st {};
  const bool regular = ::fstat(fd, &st) == 0 && S_ISREG(st.st_mode);
  if (::close(fd) != 0 && err == 0) err = errno;
  if (err == 0) return {};
  if (regular) ::unlink(path.c_str());
  return std::string(std::strerror(err)) + (regular ? " (the cut file removed)" : "");
}

}  // namespace

void write_image(const std::string& path, const cv::Mat& image) {
  std::vector<unsigned char> bytes;
  if (!backend().encode_image(std::filesystem::path(path).extension().string(), image, bytes))
    throw std::runtime_error("cannot write " + path + ": the image cannot be encoded in its extension's format");
  if (const std::string why = write_whole_file(path, bytes); !why.empty())
    throw std::runtime_error("cannot write " + path + ": " + why);
}

cv::Mat read_image(const std::string& path) { return backend().read_image(path); }

std::unique_ptr<VideoFile> open_video(const std::string& path, double fps, cv::Size frame_size) {
  // The largest side each codec's encoder takes: JPEG stores 16-bit sides and
  // FFmpeg's MJPEG encoder refuses more than 65500 (OpenCV then fell back to
  // its own AVI writer, whose JPEGs wrapped the side at 65536: a corrupt
  // video, exit 0); FFmpeg's MPEG-4 part 2 encoder refuses more than 8191 (a
  // 1280x720 camera at --scale 3 in compare mode: said to be "a missing
  // encoder").
  const std::string_view codec = video_codec(path);
  const bool avi = codec == "MJPG";
  const int max_side_px = avi ? 65500 : 8191;
  if (frame_size.width > max_side_px || frame_size.height > max_side_px) {
    throw std::runtime_error("cannot write the video " + path + ": its frames of " + std::to_string(frame_size.width) +
                             "x" + std::to_string(frame_size.height) + " px exceed " + (avi ? "JPEG" : "MPEG-4") +
                             "'s " + std::to_string(max_side_px) + " px a side (codec " + std::string(codec) +
                             "); draw smaller frames (render's --scale), " + (avi ? "" : "write an .avi (MJPG), ") +
                             "or write PNG frames to a folder");
  }
  auto video = backend().open_video(path, fps, frame_size);
  if (!video) {
    throw std::runtime_error("cannot open the video " + path + " for writing with codec " + video_codec(path) +
                             " (missing encoder or unwritable path); try " +
                             std::string(avi ? "a writable folder, or" : ".avi (MJPG) or") + " a directory of PNG frames");
  }
  return video;
}

std::unique_ptr<Window> open_window(const std::string& title) { return backend().open_window(title); }

void try_window() { backend().open_window("evlife probe")->close(); }

}  // namespace evlife::render
