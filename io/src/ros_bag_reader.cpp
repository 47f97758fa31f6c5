#include "ros_bag_reader.h"

#include "ros_topics.h"

namespace evlife::io::ros {

const TopicInfo& BagReader::select_topic(const std::string& path, const std::vector<TopicInfo>& topics,
                                         const ReaderOptions& options, Serialization serialization) {
  const TopicInfo& topic = choose_topic(path, topics, options.topic);
  topic_ = topic.name;
  decoder_ = MessageDecoder(message_kind(topic.type), serialization);
  return topic;
}

void BagReader::start() {
  load_message();
  if (decoder_.width() > 0 && decoder_.height() > 0)
    sensor_ = SensorSize{static_cast<int>(decoder_.width()), static_cast<int>(decoder_.height())};
}

std::size_t BagReader::read(std::span<Event> out) {
  std::size_t n = 0;
  while (n < out.size()) {
    if (next_ == events_.size()) {
      if (error_ || ended_) break;
      load_message();
      continue;
    }
    const std::size_t k = take_events(events_, next_, out.subspan(n));
    n += k;
    delivered_ += static_cast<std::int64_t>(k);
  }
  if (n == 0 && error_) throw *error_;
  return n;
}

std::vector<ContainerStream> BagReader::streams() const {
  std::vector<ContainerStream> s;
  for (const TopicInfo& t : topics()) s.push_back(ContainerStream{t.name, t.type, t.message_count, t.name == topic_});
  return s;
}

void BagReader::load_message() {
  events_.clear();
  next_ = 0;
  Message m;
  try {
    if (!next_message(m)) {
      ended_ = true;
      return;
    }
  } catch (const ReadError& e) {
    const std::string what = e.what();
    const std::size_t prefix = e.path().size() + 2;  // "<path>: "
    error_.emplace(e.path(), e.byte_offset(), delivered_,
                   (what.size() > prefix ? what.substr(prefix) : what) + " (after message " +
                       std::to_string(messages_read_) + " of the topic)");
    return;
  }
  ++messages_read_;
  const std::string& file = *m.file;
  const std::string message = "message " + std::to_string(m.index) + " of the topic" + std::string(m.where);
  if (const auto fault = decoder_.decode(m.data, events_)) {
    error_.emplace(file, m.offset, delivered_ + static_cast<std::int64_t>(events_.size()),
                   message + ", byte " + std::to_string(fault->byte_in_message) + " of the message: " + fault->what);
    return;
  }
  if (sensor_ && (decoder_.width() != static_cast<std::uint32_t>(sensor_->width) ||
                  decoder_.height() != static_cast<std::uint32_t>(sensor_->height))) {
    events_.clear();
    error_.emplace(file, m.offset, delivered_,
                   message + " states a " + std::to_string(decoder_.width()) + "x" +
                       std::to_string(decoder_.height()) + " sensor, the first one " +
                       std::to_string(sensor_->width) + "x" + std::to_string(sensor_->height));
  }
}

}  // namespace evlife::io::ros
