// ROS 2 MCAP files as an event stream: one event topic (ros::choose_topic),
// its CDR (or ROS 1) messages streamed chunk by chunk by mcap::McapMessages (record
// layouts: mcap_records.h; order and topic counts: mcap_messages.h), decoded
// and delivered by ros::TopicEventReader (the same faults as every ROS bag
// reader: file, byte offset of the chunk, message index; events before kept).
#include <memory>

#include "mcap_messages.h"
#include "reader_registry.h"
#include "ros_messages.h"  // EVLIFE_ROS_EVENT_MESSAGE_TYPES
#include "ros_topic_reader.h"
#include "ros_topics.h"

namespace evlife::io {
namespace {

class McapReader final : public ros::TopicEventReader {
 public:
  McapReader(const std::string& path, const ReaderOptions& options) : bag_(path) {
    const ros::TopicInfo& topic = ros::choose_topic(path, bag_.topics(), options.topic, bag_.listing_fault());
    // ros1: a ROS 1 bag's messages as `mcap convert` stores them.
    if (topic.serialization != "cdr" && topic.serialization != "ros1") {
      throw ReadError(path, -1, -1, "topic '" + topic.name + "' is encoded as '" + topic.serialization +
                                        "', not cdr (ROS 2) nor ros1");
    }
    bag_.select(topic.name);
    start(bag_.topics(), topic, topic.serialization == "ros1" ? ros::Serialization::ros1 : ros::Serialization::cdr);
  }

  std::string_view format_name() const override { return "mcap"; }
  const std::string& path() const override { return bag_.path(); }
  std::uint64_t bytes_consumed() const override { return bag_.bytes_consumed(); }

 private:
  bool next_message(Message& m) override {
    mcap::McapMessages::Message message;
    if (!bag_.next(message)) return false;
    m = Message{message.data, nullptr, static_cast<std::int64_t>(message.record_at), " (in the record at this offset)"};
    return true;
  }
  SkippedKindCount container_skipped() const override {
    return {"mcap-record-of-an-unknown-opcode", bag_.unknown_records_skipped()};
  }

  mcap::McapMessages bag_;
};

}  // namespace

namespace detail {
namespace {

SniffResult sniff_mcap(std::span<const std::byte> head, std::string_view path) {
  if (mcap::has_magic(head)) return SniffResult::by_content;
  return has_extension(path, ".mcap") ? SniffResult::by_extension : SniffResult::no;
}

std::unique_ptr<EventReader> open_mcap(const std::string& path, const ReaderOptions& options) {
  return std::make_unique<McapReader>(path, options);
}

}  // namespace

const ReaderFormat mcap_format{
    "mcap",
    "ROS 2 MCAP (.mcap; chunks uncompressed, zstd or lz4; CRCs checked; CDR messages, or ROS 1's as `mcap convert` "
    "stores a ROS 1 bag): " EVLIFE_ROS_EVENT_MESSAGE_TYPES,
    &sniff_mcap, nullptr, &open_mcap, nullptr, "topic"};

}  // namespace detail
}  // namespace evlife::io
