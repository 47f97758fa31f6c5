// ROS 2 bags (sqlite3 storage) as an event stream: one event topic, decoded
// by ros::MessageDecoder (ros_messages.h: message types, encodings, time rule).
#include <algorithm>
#include <memory>

#include "reader_registry.h"
#include "ros_messages.h"
#include "rosbag2_messages.h"
#include "ros_topics.h"

namespace evlife::io {
namespace {

using ros::MessageKind;

class Rosbag2Reader final : public EventReader {
 public:
  Rosbag2Reader(const std::string& path, const ReaderOptions& options)
      : path_(path), bag_(path), decoder_(MessageKind::not_events) {
    const ros::TopicInfo& topic = ros::choose_topic(path, bag_.topics(), options.topic);
    if (topic.serialization != "cdr") {
      throw ReadError(path, -1, -1, "topic '" + topic.name + "' is serialized as '" +
                                        topic.serialization + "', not cdr");
    }
    decoder_ = ros::MessageDecoder(ros::message_kind(topic.type));
    topic_ = topic.name;
    bag_.select(topic.name);
    // The sensor size comes from the first message.
    load_message();
    if (decoder_.width() > 0 && decoder_.height() > 0) {
      sensor_ = SensorSize{static_cast<int>(decoder_.width()), static_cast<int>(decoder_.height())};
    }
  }

  std::size_t read(std::span<Event> out) override {
    std::size_t n = 0;
    while (n < out.size()) {
      if (next_ == events_.size()) {
        if (error_ || ended_) break;
        load_message();
        continue;
      }
      const std::size_t k = ros::take_events(events_, next_, out.subspan(n));
      n += k;
      delivered_ += static_cast<std::int64_t>(k);
    }
    if (n == 0 && error_) throw *error_;
    return n;
  }

  std::optional<SensorSize> sensor_size() const override { return sensor_; }
  std::string_view format_name() const override { return "rosbag2"; }
  const std::string& path() const override { return path_; }
  std::uint64_t skipped_record_count() const override {
    return decoder_.trigger_count() + decoder_.other_count();
  }
  std::uint64_t bytes_consumed() const override { return bytes_; }
  std::uint64_t trigger_count() const override { return decoder_.trigger_count(); }
  std::vector<ContainerStream> streams() const override {
    std::vector<ContainerStream> s;
    for (const ros::TopicInfo& t : bag_.topics())
      s.push_back(ContainerStream{t.name, t.type, t.message_count, t.name == topic_});
    return s;
  }

 private:
  /// Decodes the next message into events_; sets ended_ or error_.
  void load_message() {
    events_.clear();
    next_ = 0;
    ros::Rosbag2Messages::Message m;
    if (!bag_.next(m)) {
      ended_ = true;
      return;
    }
    bytes_ += m.data.size();
    const std::optional<ros::MessageFault> fault = decoder_.decode(m.data, events_);
    if (fault) {
      error_.emplace(*m.file, -1, delivered_ + static_cast<std::int64_t>(events_.size()),
                     "message " + std::to_string(m.index) + " of the topic, byte " +
                         std::to_string(fault->byte_in_message) + " of the message: " + fault->what);
      return;
    }
    if (sensor_ && (decoder_.width() != static_cast<std::uint32_t>(sensor_->width) ||
                    decoder_.height() != static_cast<std::uint32_t>(sensor_->height))) {
      events_.clear();
      error_.emplace(*m.file, -1, delivered_,
                     "message " + std::to_string(m.index) + " of the topic states a " +
                         std::to_string(decoder_.width()) + "x" + std::to_string(decoder_.height()) +
                         " sensor, the first one " + std::to_string(sensor_->width) + "x" +
                         std::to_string(sensor_->height));
    }
  }

  std::string path_;
  std::string topic_;
  ros::Rosbag2Messages bag_;
  ros::MessageDecoder decoder_;
  std::optional<SensorSize> sensor_;
  std::vector<ros::RosEvent> events_;
  std::size_t next_ = 0;
  std::int64_t delivered_ = 0;
  std::uint64_t bytes_ = 0;
  bool ended_ = false;
  std::optional<ReadError> error_;
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
  return has_extension(path, ".db3") ? SniffResult::by_extension : SniffResult::no;
}

std::unique_ptr<EventReader> open_rosbag2(const std::string& path, const ReaderOptions& options) {
  return std::make_unique<Rosbag2Reader>(path, options);
}

bool claims_rosbag2_directory(const std::string& path) { return ros::is_rosbag2_directory(path); }

}  // namespace

const ReaderFormat rosbag2_format{
    "rosbag2",
    "ROS 2 bag, sqlite3 storage (.db3 or its folder with metadata.yaml): "
    "event_camera_msgs/EventPacket (evt3, libcaer, mono), dvs_msgs/EventArray, "
    "prophesee_event_msgs/EventArray",
    &sniff_rosbag2, nullptr, &open_rosbag2, &claims_rosbag2_directory};

}  // namespace detail
}  // namespace evlife::io
