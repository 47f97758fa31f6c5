// ROS 2 bags (sqlite3 storage) as an event stream: one event topic, decoded
// by ros::MessageDecoder (ros_messages.h: message types, encodings, time rule)
// and delivered by ros::TopicEventReader (faults: ros_topic_reader.h).
#include <algorithm>
#include <memory>

#include "reader_registry.h"
#include "ros_messages.h"  // EVLIFE_ROS_EVENT_MESSAGE_TYPES
#include "ros_topic_reader.h"
#include "rosbag2_messages.h"
#include "ros_topics.h"

namespace evlife::io {
namespace {

class Rosbag2Reader final : public ros::TopicEventReader {
 public:
  Rosbag2Reader(const std::string& path, const ReaderOptions& options) : path_(path), bag_(path) {
    const ros::TopicInfo& topic = ros::choose_topic(path, bag_.topics(), options.topic, bag_.deferred_fault());
    if (topic.serialization != "cdr") {
      throw ReadError(path, -1, -1, "topic '" + topic.name + "' is serialized as '" +
                                        topic.serialization + "', not cdr");
    }
    bag_.select(topic.name);
    start(bag_.topics(), topic, ros::Serialization::cdr);
    set_unlisted_messages(bag_.unlisted_message_count());
    set_missing_messages(bag_.missing_message_count());
  }

  std::string_view format_name() const override { return "rosbag2"; }
  const std::string& path() const override { return path_; }
  std::uint64_t bytes_consumed() const override { return bytes_; }

 private:
  bool next_message(Message& m) override {
    ros::Rosbag2Messages::Message message;
    if (!bag_.next(message)) return false;
    bytes_ += message.data.size();
    m = Message{message.data, message.file, -1, ""};
    return true;
  }

  std::string path_;
  ros::Rosbag2Messages bag_;
  std::uint64_t bytes_ = 0;
};

}  // namespace

namespace detail {
namespace {

constexpr std::string_view kSqliteMagic{"SQLite format 3\0", 16};

SniffResult sniff_rosbag2(std::span<const std::byte> head, std::string_view path) {
  if (head.size() >= kSqliteMagic.size() &&
      std::equal(kSqliteMagic.begin(), kSqliteMagic.end(), head.begin(),
                 [](char a, std::byte b) { return static_cast<std::byte>(a) == b; })) {
    return SniffResult::by_content;
  }
  // A file-compressed bag's NAME.db3.zstd: its name and magic; the magic alone
  // (standard input) ranks as a name would, zstd being no format of its own.
  if (ros::is_zstd_stream(head))
    return has_extension(path, ".db3.zstd") ? SniffResult::by_content : SniffResult::by_extension;
  return has_extension(path, ".db3") || has_extension(path, ".db3.zstd") ? SniffResult::by_extension : SniffResult::no;
}

std::unique_ptr<EventReader> open_rosbag2(const std::string& path, const ReaderOptions& options) {
  return std::make_unique<Rosbag2Reader>(path, options);
}

bool claims_rosbag2_directory(const std::string& path) { return ros::is_rosbag2_directory(path); }

}  // namespace

const ReaderFormat rosbag2_format{
    "rosbag2",
    "ROS 2 bag, sqlite3 storage (.db3, a file-compressed bag's .db3.zstd, or the bag folder): "
    EVLIFE_ROS_EVENT_MESSAGE_TYPES,
    &sniff_rosbag2, nullptr, &open_rosbag2, &claims_rosbag2_directory, "topic"};

}  // namespace detail
}  // namespace evlife::io
