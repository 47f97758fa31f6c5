// Private: the topic a ROS bag reader delivers (shared by the ROS 1 and ROS 2
// bag readers).
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "rosbag2_messages.h"

namespace evlife::io::ros {

/// Adds a connection's or channel's `topic` to `topics` (`by_name` indexes
/// them): a name seen before adds its messages, and another type on it is
/// kept as `other_type`, which choose_topic refuses (one decoder per topic;
/// every bag format records the type per connection, not per name).
void add_topic(std::vector<TopicInfo>& topics, std::map<std::string, std::size_t>& by_name, TopicInfo topic);

/// `wanted` if given (it must exist and be an event type), else the only
/// event topic; throws ReadError naming `path` and listing the topics. Where
/// the topic is not there and `listing_cut` (the fault of a later file or
/// chunk, whose topics were not listed) is given, throws that fault instead.
const TopicInfo& choose_topic(const std::string& path, const std::vector<TopicInfo>& topics,
                              const std::string& wanted, const ReadError* listing_cut = nullptr);

}  // namespace evlife::io::ros
