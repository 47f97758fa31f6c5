// Private: what every ROS bag reader (rosbag1, rosbag2, mcap) shares: the
// chosen event topic's messages decoded by ros::MessageDecoder and delivered
// in batches; the sensor size from the first message (a later message stating
// another size is a fault); faults of the container (ContainerFault) and of a
// message kept until the events before them are delivered, then thrown as
// ReadError naming the file, the byte offset and the topic's message index.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "evlife/io/event_reader.h"
#include "prophesee_time_high.h"  // prophesee_skipped_kinds
#include "ros_messages.h"
#include "rosbag2_messages.h"  // TopicInfo

namespace evlife::io::ros {

/// A fault of a bag container (truncation, corrupt chunk, ...), re-reported
/// with the message count.
class ContainerFault : public ReadError {
 public:
  ContainerFault(const std::string& path, std::int64_t byte_offset, const std::string& reason)
      : ReadError(path, byte_offset, -1, reason) {}
};

class TopicEventReader : public EventReader {
 public:
  std::size_t read(std::span<Event> out) final;
  std::optional<SensorSize> sensor_size() const final { return sensor_; }
  std::uint64_t skipped_record_count() const final {
    return decoder_.trigger_count() + decoder_.other_count() + decoder_.before_time_base_count() +
           decoder_.before_address_count() + decoder_.libcaer_invalid_count() + container_skipped().count +
           unlisted_messages_ + missing_messages_;
  }
  std::vector<SkippedKindCount> skipped_record_kinds() const final {
    auto kinds = prophesee_skipped_kinds(decoder_.trigger_count(), decoder_.other_count(),
                                         decoder_.before_time_base_count(), decoder_.before_address_count());
    if (const std::uint64_t n = decoder_.libcaer_invalid_count(); n > 0) kinds.push_back({"libcaer-event-marked-invalid", n});
    if (const SkippedKindCount c = container_skipped(); c.count > 0) kinds.push_back(c);
    if (unlisted_messages_ > 0) kinds.push_back({"message-of-a-topic-id-no-topics-row-lists", unlisted_messages_});
    if (missing_messages_ > 0) kinds.push_back({"message-metadata-yaml-counts-and-no-file-holds", missing_messages_});
    return kinds;
  }
  std::uint64_t trigger_count() const final { return decoder_.trigger_count(); }
  std::vector<ContainerStream> streams() const final;
  /// The byte offset of the record or chunk holding the message of an event
  /// delivered by the last read() (a time-order fault's location).
  std::int64_t byte_offset_of_event(std::int64_t event_index) const final;

 protected:
  struct Message {
    std::span<const std::uint8_t> data;  ///< the serialized message
    const std::string* file = nullptr;   ///< the file holding it
    std::int64_t byte_offset = -1;       ///< of its record or chunk (-1: not known)
    const char* in_record = "";          ///< says what byte_offset points at, e.g. " (in the chunk at this offset)"
  };
  /// The next message of the topic; false at the end. Throws ReadError
  /// (ContainerFault for the container's own faults).
  virtual bool next_message(Message& m) = 0;

  /// Call at the end of the derived constructor, after choosing `topic`
  /// among `topics`: decodes the first message (the sensor size).
  void start(const std::vector<TopicInfo>& topics, const TopicInfo& topic, Serialization serialization);
  /// A rosbag2's messages whose topic_id no topics row lists (streams() shows them).
  void set_unlisted_messages(std::uint64_t count) noexcept { unlisted_messages_ = count; }
  /// A rosbag2's messages of the topic that metadata.yaml counts and no file holds.
  void set_missing_messages(std::uint64_t count) noexcept { missing_messages_ = count; }
  /// Records of the container skipped on purpose so far (an MCAP file's of
  /// unknown opcodes, which may have held messages): shown as skipped records.
  virtual SkippedKindCount container_skipped() const { return {}; }

 private:
  void load_message();

  std::vector<TopicInfo> topics_;
  std::uint64_t unlisted_messages_ = 0;
  std::uint64_t missing_messages_ = 0;
  std::string topic_;
  MessageDecoder decoder_{MessageKind::not_events};
  std::optional<SensorSize> sensor_;
  std::vector<RosEvent> events_;
  std::size_t next_ = 0;
  std::int64_t delivered_ = 0;
  std::uint64_t messages_ = 0;  ///< of the topic, taken from the container so far
  /// Where the messages of the last read() begin: their first event's index and
  /// their byte offset (trimmed to the current message at each read()).
  struct MessageStart {
    std::int64_t first_event = 0;
    std::int64_t byte_offset = -1;
  };
  std::vector<MessageStart> message_starts_;
  bool ended_ = false;
  std::optional<ReadError> error_;
};

}  // namespace evlife::io::ros
