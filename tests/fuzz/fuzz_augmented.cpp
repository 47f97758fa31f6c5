// libFuzzer target: the readers of evlife's own augmented output (.csv and
// .bin, sniffed by magic), which `evlife render` and `evlife eval` read back.
// Only ReadError may end a read; records must carry polarity +-1.
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "evlife/io/augmented_event_reader.h"
#include "fuzz_input_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string& path = evlife::fuzz::write_input_file(data, size, ".csv");
  static bool cleanup = (evlife::fuzz::remove_input_file_at_exit(path), true);
  (void)cleanup;
  try {
    auto reader = evlife::io::open_augmented_reader(path);
    std::array<evlife::AugmentedEvent, 61> batch{};
    for (std::size_t total = 0; total < (std::size_t{1} << 20);) {
      const std::size_t n = reader->read(batch);
      if (n == 0) break;
      if (n > batch.size()) std::abort();
      total += n;
    }
  } catch (const evlife::io::ReadError&) {
    // refused with a message naming the file: fine
  }
  return 0;
}
