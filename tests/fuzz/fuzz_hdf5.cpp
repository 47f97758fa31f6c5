// libFuzzer target: the hdf5 reader (file extension .h5), through
// open_event_reader, read whole and then from the middle time by its binary
// search (skip_events_before). See fuzz_event_reader.h for what counts as a
// finding.
#include <cstddef>
#include <cstdint>

#include "fuzz_event_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return evlife::fuzz::fuzz_event_reader(data, size, ".h5", std::size_t{1} << 20, /*also_skip=*/true);
}
