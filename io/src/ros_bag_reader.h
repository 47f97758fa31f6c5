// Private: what the ROS bag readers (ROS 1 .bag, ROS 2 .db3) share: one
// event topic decoded message by message by ros::MessageDecoder, its events
// handed out in order, the sensor size of the first message held for the
// rest, and every fault reported after the events before it. A container
// supplies the topics and the topic's messages in order (next_message()).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "evlife/io/event_reader.h"
#include "ros_messages.h"
#include "rosbag2_messages.h"

namespace evlife::io::ros {

class BagReader : public EventReader {
 public:
  std::size_t read(std::span<Event> out) final;
  std::optional<SensorSize> sensor_size() const final { return sensor_; }
  std::uint64_t skipped_record_count() const final {
    return decoder_.trigger_count() + decoder_.other_count();
  }
  std::uint64_t trigger_count() const final { return decoder_.trigger_count(); }
  std::vector<ContainerStream> streams() const final;

 protected:
  /// One message of the topic, as the container found it.
  struct Message {
    std::span<const std::uint8_t> data;  ///< valid until the next next_message()
    std::uint64_t index = 0;             ///< 0-based among the topic's messages
    const std::string* file = nullptr;   ///< the file it is in
    std::int64_t offset = -1;            ///< byte offset of what holds it; -1 = unknown
    std::string_view where;              ///< said after "message N of the topic" in errors
  };

  BagReader() : decoder_(MessageKind::not_events) {}

  /// Chooses the topic among `topics` (ros::choose_topic: --topic, else the
  /// only event topic) and sets the decoder up for its type.
  const TopicInfo& select_topic(const std::string& path, const std::vector<TopicInfo>& topics,
                                const ReaderOptions& options, Serialization serialization);
  /// Decodes the first message (the sensor size comes from it); the last
  /// step of a derived constructor.
  void start();

  /// The next message of the selected topic; false at the end. May throw
  /// ReadError (kept and reported after the events before it).
  virtual bool next_message(Message& m) = 0;
  /// Every topic of the bag with its type and message count.
  virtual const std::vector<TopicInfo>& topics() const = 0;

  const std::string& topic() const { return topic_; }

 private:
  void load_message();

  MessageDecoder decoder_;
  std::string topic_;
  std::optional<SensorSize> sensor_;
  std::vector<RosEvent> events_;
  std::size_t next_ = 0;
  std::int64_t delivered_ = 0;
  std::uint64_t messages_read_ = 0;
  bool ended_ = false;
  std::optional<ReadError> error_;
};

}  // namespace evlife::io::ros
