// ROS 2 MCAP files as an event stream: one event topic (ros::choose_topic),
// its CDR messages streamed chunk by chunk by mcap::McapMessages (record
// layouts: mcap_records.h; order and topic counts: mcap_messages.h) and
// decoded by ros::MessageDecoder (ros_messages.h: message types, encodings,
// time rule). Faults are reported as by the ROS 1 bag reader: file, byte
// offset of the chunk, message index of the topic; events before them kept.
#include <memory>

#include "mcap_messages.h"
#include "reader_registry.h"
#include "ros_messages.h"
#include "ros_topics.h"

namespace evlife::io {
namespace {

class McapReader final : public EventReader {
 public:
  McapReader(const std::string& path, const ReaderOptions& options)
      : bag_(path), decoder_(ros::MessageKind::not_events) {
    const ros::TopicInfo& topic = ros::choose_topic(path, bag_.topics(), options.topic);
    if (topic.serialization != "cdr") {
      throw ReadError(path, -1, -1, "topic '" + topic.name + "' is encoded as '" + topic.serialization +
                                        "', not cdr (ROS 2)");
    }
    decoder_ = ros::MessageDecoder(ros::message_kind(topic.type));
    topic_ = topic.name;
    bag_.select(topic.name);
    load_message();  // the sensor size comes from the first message
    if (decoder_.width() > 0 && decoder_.height() > 0)
      sensor_ = SensorSize{static_cast<int>(decoder_.width()), static_cast<int>(decoder_.height())};
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
  std::string_view format_name() const override { return "mcap"; }
  const std::string& path() const override { return bag_.path(); }
  std::uint64_t skipped_record_count() const override {
    return decoder_.trigger_count() + decoder_.other_count();
  }
  std::uint64_t trigger_count() const override { return decoder_.trigger_count(); }
  std::uint64_t bytes_consumed() const override { return bag_.bytes_consumed(); }
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
    mcap::McapMessages::Message m;
    try {
      if (!bag_.next(m)) {
        ended_ = true;
        return;
      }
    } catch (const mcap::Fault& e) {
      error_.emplace(bag_.path(), e.byte_offset(), delivered_,
                     e.reason() + " (after " + std::to_string(messages_) + " messages of the topic)");
      return;
    }
    messages_ = m.index + 1;
    const auto at = static_cast<std::int64_t>(m.record_at);
    if (const auto fault = decoder_.decode(m.data, events_)) {
      error_.emplace(bag_.path(), at, delivered_ + static_cast<std::int64_t>(events_.size()),
                     "message " + std::to_string(m.index) + " of the topic (in the record at this offset), byte " +
                         std::to_string(fault->byte_in_message) + " of the message: " + fault->what);
      return;
    }
    if (sensor_ && (decoder_.width() != static_cast<std::uint32_t>(sensor_->width) ||
                    decoder_.height() != static_cast<std::uint32_t>(sensor_->height))) {
      events_.clear();
      error_.emplace(bag_.path(), at, delivered_,
                     "message " + std::to_string(m.index) + " of the topic states a " +
                         std::to_string(decoder_.width()) + "x" + std::to_string(decoder_.height()) +
                         " sensor, the first one " + std::to_string(sensor_->width) + "x" +
                         std::to_string(sensor_->height));
    }
  }

  mcap::McapMessages bag_;
  ros::MessageDecoder decoder_;
  std::string topic_;
  std::optional<SensorSize> sensor_;
  std::vector<ros::RosEvent> events_;
  std::size_t next_ = 0;
  std::int64_t delivered_ = 0;
  std::uint64_t messages_ = 0;  // of the topic, read so far
  bool ended_ = false;
  std::optional<ReadError> error_;
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
    "ROS 2 MCAP (.mcap; chunks uncompressed, zstd or lz4; CDR messages): event_camera_msgs/EventPacket "
    "(evt3, libcaer, mono), dvs_msgs/EventArray, prophesee_event_msgs/EventArray",
    &sniff_mcap, nullptr, &open_mcap};

}  // namespace detail
}  // namespace evlife::io
