#include "evlife/io/stream_copy_name.h"

#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <utility>

namespace evlife::io {
namespace {

struct CopyNames {
  std::mutex mutex;
  std::map<std::string, std::string, std::less<>> display_name_of_copy;
};

// One for the process: a command registers its copy, readers on any thread
// (PrefetchReader, the engine's source) look it up.
CopyNames& copy_names() {
  static CopyNames names;
  return names;
}

}  // namespace

StreamCopyName::StreamCopyName(std::string copy_path, std::string display_name) : copy_path_(std::move(copy_path)) {
  CopyNames& names = copy_names();
  const std::lock_guard lock(names.mutex);
  names.display_name_of_copy.insert_or_assign(copy_path_, std::move(display_name));
}

StreamCopyName::~StreamCopyName() {
  CopyNames& names = copy_names();
  const std::lock_guard lock(names.mutex);
  names.display_name_of_copy.erase(copy_path_);
}

std::string name_in_messages(const std::string& path) {
  CopyNames& names = copy_names();
  const std::lock_guard lock(names.mutex);
  const auto found = names.display_name_of_copy.find(path);
  return found == names.display_name_of_copy.end() ? path : found->second;
}

}  // namespace evlife::io
