// libFuzzer target: the ROS 1 bag reader (records, index, bz2/lz4/none
// chunks, ROS 1 message decoding), through open_event_reader (extension
// .bag). See fuzz_event_reader.h for what counts as a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz_event_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return evlife::fuzz::fuzz_event_reader(data, size, ".bag");
}
