// Private: the topic a ROS bag reader delivers (shared by the ROS 1 and ROS 2
// bag readers).
#pragma once

#include <string>
#include <vector>

#include "rosbag2_messages.h"

namespace evlife::io::ros {

/// `wanted` if given (it must exist and be an event type), else the only
/// event topic; throws ReadError naming `path` and listing the topics.
const TopicInfo& choose_topic(const std::string& path, const std::vector<TopicInfo>& topics,
                              const std::string& wanted);

}  // namespace evlife::io::ros
