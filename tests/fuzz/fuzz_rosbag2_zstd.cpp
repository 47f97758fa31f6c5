// libFuzzer target: a file-compressed ROS 2 bag's NAME.db3.zstd (ros2 bag
// record --compression-mode file): the zstd stream decompressed into a
// temporary .db3 (its write, the space check, its removal), then the bag
// reader as fuzz_rosbag2. See fuzz_event_reader.h for what counts as a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz_event_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return evlife::fuzz::fuzz_event_reader(data, size, ".db3.zstd");
}
