// libFuzzer target: the NumPy .npy reader (file extension .npy; its header's
// Python literal parser, structured and plain layouts), through
// open_event_reader. See fuzz_event_reader.h for what counts as a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz_event_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return evlife::fuzz::fuzz_event_reader(data, size, ".npy");
}
