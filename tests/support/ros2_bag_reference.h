// The shared ROS 2 bags (../shared/data/rosbag) as the ROS tests' reference:
// decoded message by message through the rosbag2 container, and the checksums
// event_camera_codecs' test/decoder_test.cpp states for them
// (../shared/data/PROVENANCE.md, "ROS bags"). Header-only: for the white-box
// ROS tests, which see io/formats/src.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "ros_messages.h"
#include "rosbag2_messages.h"

namespace evlife::test {

using RosMessages = std::vector<std::vector<io::ros::RosEvent>>;

/// Σt (ns, u64 wrapping), Σx, Σy, Σp (p in {0, 1}), event count.
struct RosSums {
  std::uint64_t t = 0, x = 0, y = 0, p = 0, events = 0;
  bool operator==(const RosSums&) const = default;
};

/// The checksums of the shared bags, by payload encoding.
inline const std::map<std::string, RosSums> kRosBagSums = {
    {"evt3", {1222326831810000u, 42078718u, 31656267u, 41439u, 82469u}},
    {"libcaer", {15762826572202229126u, 111651612u, 82801007u, 181908u, 334331u}},
    {"mono", {4950000u, 34450u, 26450u, 50u, 100u}}};

inline RosSums ros_sums(const RosMessages& messages) {
  RosSums s;
  for (const auto& m : messages) {
    for (const io::ros::RosEvent& e : m) {
      s.t += static_cast<std::uint64_t>(e.t_ns);
      s.x += e.x;
      s.y += e.y;
      s.p += e.p > 0 ? 1u : 0u;
      ++s.events;
    }
  }
  return s;
}

/// The events of each message of a ROS 2 bag's one topic (a test failure
/// for a message that does not decode).
inline RosMessages decode_db3(const std::string& bag_path, io::Evt3TriggerSink* triggers = nullptr) {
  io::ros::Rosbag2Messages bag(bag_path);
  EXPECT_EQ(bag.topics().size(), 1u) << bag_path;
  const io::ros::TopicInfo topic = bag.topics().at(0);
  io::ros::MessageDecoder decoder(io::ros::message_kind(topic.type));
  decoder.set_trigger_sink(triggers);
  bag.select(topic.name);
  RosMessages r;
  io::ros::Rosbag2Messages::Message m;
  std::vector<io::ros::RosEvent> events;
  while (bag.next(m)) {
    const auto fault = decoder.decode(m.data, events);
    EXPECT_FALSE(fault) << bag_path << " message " << m.index << ": " << fault->what;
    r.push_back(events);
  }
  return r;
}

}  // namespace evlife::test
