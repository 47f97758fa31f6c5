// libFuzzer target: the ROS EventPacket 'evt3' payload decoder (the shared
// Evt3Decoder behind ros::decode_evt3). Input layout and findings:
// fuzz_ros_payload.h. The decoder state carries over message borders, so a
// payload cut in two messages (at a word border) decodes to the same events.
#include "fuzz_ros_payload.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace evlife;
  const auto in = fuzz::parse_payload_input(data, size);
  if (!in) return 0;
  const auto geometry = [&](io::Evt3Decoder& d) {
    d.set_geometry(in->width == 0 ? 2048u : in->width, in->height == 0 ? 2048u : in->height);
  };
  std::vector<Event> scratch;
  io::Evt3Decoder one;
  geometry(one);
  std::vector<io::ros::RosEvent> whole;
  const auto fault = io::ros::decode_evt3(in->payload, one, scratch, whole);
  fuzz::check_events(whole, in->width, in->height);
  io::Evt3Decoder two;
  geometry(two);
  std::vector<io::ros::RosEvent> cut;
  std::vector<io::ros::RosEvent> part;
  auto fault_cut = io::ros::decode_evt3(in->payload.first(in->cut), two, scratch, part);
  cut = part;
  if (!fault_cut) {
    part.clear();
    fault_cut = io::ros::decode_evt3(in->payload.subspan(in->cut), two, scratch, part);
    cut.insert(cut.end(), part.begin(), part.end());
  }
  if (fault.has_value() != fault_cut.has_value()) fuzz::ros_contract_violation("cut decode faults differently");
  if (!fuzz::same_events(whole, cut)) fuzz::ros_contract_violation("cut decode gives other events");
  return 0;
}
