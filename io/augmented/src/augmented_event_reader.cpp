#include "evlife/io/augmented_event_reader.h"

#include <cstring>

#include "augmented_bin_format.h"
#include "augmented_formats.h"
#include "input_file.h"

namespace evlife::io {

std::unique_ptr<AugmentedEventReader> open_augmented_reader(const std::string& path) {
  char head[8] = {};
  {
    const detail::InputFile file(path);
    file.read_at(0, std::as_writable_bytes(std::span(head)));
  }
  if (std::memcmp(head, detail::augmented_bin::kMagic.data(), 8) == 0)
    return detail::open_augmented_bin_reader(path);
  return detail::open_augmented_csv_reader(path);  // checks its header
}

}  // namespace evlife::io
