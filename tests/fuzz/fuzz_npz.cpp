// libFuzzer target: the NumPy .npz reader (file extension .npz; its ZIP
// directory, stored and deflated members, CRC-32s, the arrays' .npy headers,
// one array of events or one per column), through open_event_reader. See
// fuzz_event_reader.h for what counts as a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz_event_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return evlife::fuzz::fuzz_event_reader(data, size, ".npz");
}
