// libFuzzer target: the ROS EventPacket 'libcaer_cmp' payload decoder
// (io/formats/src/ros_messages.h). Input layout: fuzz_ros_payload.h. Checked
// besides its contract: without a fault, one event per ADDR_Y word and per bit
// of each VECT_8 word (counted here from the words); the words' x, base row and
// polarity carry over a message border (the time does not: each message starts
// at its time_base), so a payload cut in two gives the same coordinates.
#include <bit>

#include "fuzz_ros_payload.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace evlife;
  const auto in = fuzz::parse_payload_input(data, size);
  if (!in) return 0;
  io::ros::LibcaerCmpState one;
  std::vector<io::ros::RosEvent> whole;
  const auto fault = io::ros::decode_libcaer_cmp(in->payload, in->time_base, in->width, in->height, one, whole);
  fuzz::check_events(whole, in->width, in->height);
  if (fault && fault->byte_in_message > in->payload.size()) fuzz::ros_contract_violation("fault beyond the payload");
  if (!fault) {
    std::size_t expected = 0;
    for (std::size_t at = 0; at + 1 < in->payload.size(); at += 2) {
      const unsigned code = in->payload[at + 1] >> 4;
      expected += code == 3 ? 1u : code == 5 ? static_cast<std::size_t>(std::popcount(in->payload[at])) : 0u;
    }
    if (whole.size() != expected) fuzz::ros_contract_violation("events lost without a fault");
  }
  io::ros::LibcaerCmpState two;
  std::vector<io::ros::RosEvent> cut;
  auto fault_cut = io::ros::decode_libcaer_cmp(in->payload.first(in->cut), in->time_base, in->width, in->height, two, cut);
  if (!fault_cut) {
    fault_cut = io::ros::decode_libcaer_cmp(in->payload.subspan(in->cut), in->time_base, in->width, in->height, two, cut);
  }
  if (fault.has_value() != fault_cut.has_value()) fuzz::ros_contract_violation("cut decode faults differently");
  if (whole.size() != cut.size()) fuzz::ros_contract_violation("cut decode gives another count");
  for (std::size_t i = 0; i < whole.size(); ++i) {
    if (whole[i].x != cut[i].x || whole[i].y != cut[i].y || whole[i].p != cut[i].p)
      fuzz::ros_contract_violation("cut decode gives other coordinates");
  }
  return 0;
}
