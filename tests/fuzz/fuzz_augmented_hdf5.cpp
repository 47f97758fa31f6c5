// libFuzzer target: evlife's augmented HDF5 output read back (the HDF5
// reader's event columns with the lifetime, vx, vy and prediction_error
// columns beside them), as `evlife render`, `eval`, `info`, `convert` and
// Python's read_augmented read it. Only ReadError may end a read.
#include "fuzz_augmented_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return evlife::fuzz::fuzz_augmented_reader(data, size, ".h5");
}
