// The body of the augmented-output fuzz targets: the input written as a file
// named `extension`, read through open_augmented_reader (which sniffs the
// format) in odd batches. Only ReadError may end a read.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "evlife/io/augmented_event_reader.h"
#include "fuzz_input_file.h"

namespace evlife::fuzz {

inline int fuzz_augmented_reader(const std::uint8_t* data, std::size_t size, const char* extension) {
  const std::string& path = write_input_file(data, size, extension);
  static bool cleanup = (remove_input_file_at_exit(path), true);
  (void)cleanup;
  try {
    auto reader = io::open_augmented_reader(path);
    std::array<AugmentedEvent, 61> batch{};
    for (std::size_t total = 0; total < (std::size_t{1} << 20);) {
      const std::size_t n = reader->read(batch);
      if (n == 0) break;
      if (n > batch.size()) std::abort();
      for (std::size_t i = 0; i < n; ++i) {
        if (batch[i].event.p != 1 && batch[i].event.p != -1) std::abort();  // the readers' own rule
      }
      total += n;
    }
  } catch (const io::ReadError&) {
    // refused with a message naming the file: fine
  }
  return 0;
}

}  // namespace evlife::fuzz
