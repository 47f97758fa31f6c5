// The name a temporary copy of a stream goes by in messages. A command given
// `-` (stdin) or a named pipe reads a copy of it in $TMPDIR (the readers read
// a file's start again, several formats need its size); the errors and
// warnings about that copy name what the user gave ("stdin", the pipe's path
// as typed), not a temporary path they never saw and that is gone by then.
#pragma once

#include <string>

namespace evlife::io {

/// While it lives, `copy_path` is named `display_name` in messages
/// (name_in_messages, so ReadError). Process-wide: a command's readers may
/// run on other threads (PrefetchReader, the engine's source). The lookup
/// takes a mutex: for messages, never per event.
class StreamCopyName {
 public:
  StreamCopyName(std::string copy_path, std::string display_name);
  ~StreamCopyName();
  StreamCopyName(const StreamCopyName&) = delete;
  StreamCopyName& operator=(const StreamCopyName&) = delete;

 private:
  std::string copy_path_;
};

/// The display name of a copy registered by StreamCopyName, else `path` unchanged.
std::string name_in_messages(const std::string& path);

}  // namespace evlife::io
