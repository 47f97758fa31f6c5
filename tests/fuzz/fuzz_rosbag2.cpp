// libFuzzer target: the ROS 2 bag reader (rosbag2 sqlite3 file: the topics
// and messages tables, message types, ROS 2 CDR decoding of every event
// message), through open_event_reader (extension .db3). sqlite3 parses the
// container itself; what is fuzzed is what evlife does with what it returns.
// See fuzz_event_reader.h for what counts as a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz_event_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return evlife::fuzz::fuzz_event_reader(data, size, ".db3");
}
