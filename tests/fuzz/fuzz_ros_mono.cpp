// libFuzzer target: the ROS EventPacket 'mono' payload decoder
// (io/formats/src/ros_messages.h). Input layout and findings: fuzz_ros_payload.h.
// Events are independent of each other except for the clock, so the cut
// decode must equal the whole one up to the first fault.
#include "fuzz_ros_payload.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace evlife;
  const auto in = fuzz::parse_payload_input(data, size);
  if (!in) return 0;
  std::vector<io::ros::RosEvent> whole;
  const auto fault = io::ros::decode_mono(in->payload, in->time_base, in->width, in->height, whole);
  fuzz::check_events(whole, in->width, in->height);
  if (fault && fault->byte_in_message > in->payload.size()) fuzz::ros_contract_violation("fault beyond the payload");
  if (!fault && whole.size() != in->payload.size() / 8) fuzz::ros_contract_violation("events lost without a fault");
  return 0;
}
