// libFuzzer target: the ROS EventPacket 'mono' payload decoder
// (io/formats/src/ros_messages.h). Input layout, checks and findings:
// fuzz_ros_payload.h (fuzz_word_payload).
#include "fuzz_ros_payload.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return evlife::fuzz::fuzz_word_payload(
      data, size,
      [](std::span<const std::uint8_t> payload, std::uint64_t time_base, std::uint32_t width, std::uint32_t height,
         std::vector<evlife::io::ros::RosEvent>& out, std::uint64_t& /*skipped: none*/) {
        return evlife::io::ros::decode_mono(payload, time_base, width, height, out);
      });
}
