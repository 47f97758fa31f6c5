// libFuzzer target: the ROS EventPacket 'libcaer' payload decoder
// (io/formats/src/ros_messages.h). Input layout, checks and findings:
// fuzz_ros_payload.h (fuzz_word_payload).
#include "fuzz_ros_payload.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return evlife::fuzz::fuzz_word_payload(data, size, &evlife::io::ros::decode_libcaer);
}
