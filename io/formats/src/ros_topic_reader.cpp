#include "ros_topic_reader.h"

#include <algorithm>

namespace evlife::io::ros {

void TopicEventReader::start(const std::vector<TopicInfo>& topics, const TopicInfo& topic,
                             Serialization serialization) {
  topics_ = topics;
  topic_ = topic.name;
  decoder_ = MessageDecoder(message_kind(topic.type), serialization);
  load_message();
  // A first message that states no size (0), or one beyond any camera's (its fault is error_), states none.
  const auto side = [](std::uint32_t v) { return static_cast<int>(std::min<std::uint32_t>(v, kMaxSensorSide + 1)); };
  if (const SensorSize s{side(decoder_.width()), side(decoder_.height())}; s.within_camera_limits()) sensor_ = s;
}

std::size_t TopicEventReader::read(std::span<Event> out) {
  if (message_starts_.size() > 1) message_starts_.erase(message_starts_.begin(), message_starts_.end() - 1);
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

std::int64_t TopicEventReader::byte_offset_of_event(std::int64_t event_index) const {
  for (auto m = message_starts_.rbegin(); m != message_starts_.rend(); ++m)
    if (m->first_event <= event_index) return m->byte_offset;
  return -1;
}

std::vector<ContainerStream> TopicEventReader::streams() const {
  std::vector<ContainerStream> s;
  for (const TopicInfo& t : topics_) {
    s.push_back(ContainerStream{t.name, t.other_type.empty() ? t.type : t.type + " and " + t.other_type,
                                t.message_count, t.name == topic_});
  }
  if (unlisted_messages_ > 0)
    s.push_back(ContainerStream{"(topic ids no topics row lists)", "(unknown: not read)", unlisted_messages_, false});
  return s;
}

void TopicEventReader::load_message() {
  events_.clear();
  next_ = 0;
  Message m;
  try {
    if (!next_message(m)) {
      ended_ = true;
      return;
    }
  } catch (const ReadError& e) {
    // The bare reason: the location is this error's own (what() repeated the byte offset).
    error_.emplace(e.path(), e.byte_offset(), delivered_,
                   e.reason() + " (after " + std::to_string(messages_) + " messages of the topic)");
    return;
  }
  const std::uint64_t index = messages_++;
  message_starts_.push_back({delivered_, m.byte_offset});
  const std::string& file = m.file != nullptr ? *m.file : path();
  if (const auto fault = decoder_.decode(m.data, events_)) {
    error_.emplace(file, m.byte_offset, delivered_ + static_cast<std::int64_t>(events_.size()),
                   "message " + std::to_string(index) + " of the topic" + m.in_record + ", byte " +
                       std::to_string(fault->byte_in_message) + " of the message: " + fault->what);
    return;
  }
  if (sensor_ && (decoder_.width() != static_cast<std::uint32_t>(sensor_->width) ||
                  decoder_.height() != static_cast<std::uint32_t>(sensor_->height))) {
    events_.clear();
    error_.emplace(file, m.byte_offset, delivered_,
                   "message " + std::to_string(index) + " of the topic" + m.in_record + " states a " +
                       std::to_string(decoder_.width()) + "x" + std::to_string(decoder_.height()) +
                       " sensor, the first one " + std::to_string(sensor_->width) + "x" +
                       std::to_string(sensor_->height));
  }
}

}  // namespace evlife::io::ros
