// libFuzzer target: the readers of evlife's own augmented output (.csv and
// .bin, sniffed by magic), which `evlife render` and `evlife eval` read back.
// Only ReadError may end a read; records must carry polarity +-1.
#include "fuzz_augmented_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return evlife::fuzz::fuzz_augmented_reader(data, size, ".csv");
}
