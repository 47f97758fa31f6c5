// libFuzzer target: a whole CDR message through ros::MessageDecoder (the
// EventPacket parser with its evt3 / libcaer / mono payloads, and the
// dvs_msgs / prophesee_event_msgs EventArray parser). The first input byte
// picks the message type (even: EventPacket, odd: EventArray); the rest is
// the message, decoded twice by one decoder (the state carries over).
// Findings: a crash or sanitizer report, or an event outside the sensor the
// message states, a polarity other than ±1, a negative time, a fault offset
// beyond the message.
#include "fuzz_ros_payload.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace evlife;
  if (size < 1) return 0;
  const auto kind = (data[0] & 1) == 0 ? io::ros::MessageKind::event_packet : io::ros::MessageKind::event_array;
  const std::span<const std::uint8_t> message(data + 1, size - 1);
  io::ros::MessageDecoder decoder(kind);
  std::vector<io::ros::RosEvent> events;
  for (int round = 0; round < 2; ++round) {
    const auto fault = decoder.decode(message, events);
    if (fault && fault->byte_in_message > message.size()) fuzz::ros_contract_violation("fault beyond the message");
    fuzz::check_events(events, decoder.width(), decoder.height());
  }
  return 0;
}
