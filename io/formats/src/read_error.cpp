#include <string>

#include "evlife/io/event_reader.h"

namespace evlife::io {
namespace {

// "<path>: <what> (event index N, byte offset B)" — where parts are known.
std::string compose(const std::string& path, std::int64_t byte_offset, std::int64_t event_index,
                    const std::string& what) {
  std::string message = path + ": " + what;
  if (event_index >= 0 || byte_offset >= 0) {
    message += " (";
    if (event_index >= 0) message += "event index " + std::to_string(event_index);
    if (event_index >= 0 && byte_offset >= 0) message += ", ";
    if (byte_offset >= 0) message += "byte offset " + std::to_string(byte_offset);
    message += ")";
  }
  return message;
}

}  // namespace

ReadError::ReadError(const std::string& path, std::int64_t byte_offset, std::int64_t event_index,
                     const std::string& what)
    : std::runtime_error(compose(path, byte_offset, event_index, what)),
      path_(path),
      byte_offset_(byte_offset),
      event_index_(event_index) {}

}  // namespace evlife::io
