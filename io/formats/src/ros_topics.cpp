#include "ros_topics.h"

#include <algorithm>
#include <utility>

#include "evlife/io/event_reader.h"
#include "ros_messages.h"

namespace evlife::io::ros {
namespace {

std::string topic_list(const std::vector<TopicInfo>& topics) {
  std::string s;
  for (const TopicInfo& t : topics)
    s += "\n  " + t.name + " (" + t.type + (t.other_type.empty() ? "" : " and " + t.other_type) + ", " +
         std::to_string(t.message_count) + " messages)";
  return s.empty() ? "\n  (none)" : s;
}

// The topic chosen, unless it mixes two types.
const TopicInfo& of_one_type(const std::string& path, const TopicInfo& t) {
  if (!t.other_type.empty()) {
    throw ReadError(path, -1, -1,
                    "topic '" + t.name + "' holds messages of two types, " + t.type + " and " + t.other_type +
                        " (connections or channels of one name): evlife decodes a topic of one type");
  }
  return t;
}

}  // namespace

void add_topic(std::vector<TopicInfo>& topics, std::map<std::string, std::size_t>& by_name, TopicInfo topic) {
  const auto [it, added] = by_name.emplace(topic.name, topics.size());
  if (added) {
    topics.push_back(std::move(topic));
    return;
  }
  TopicInfo& known = topics[it->second];
  known.message_count += topic.message_count;
  if (topic.type != known.type && known.other_type.empty()) known.other_type = topic.type;
}

/// The event topic to read: `wanted` if given, else the only one.
const TopicInfo& choose_topic(const std::string& path, const std::vector<TopicInfo>& topics,
                              const std::string& wanted, const ReadError* listing_cut) {
  if (!wanted.empty()) {
    const auto it = std::find_if(topics.begin(), topics.end(),
                                 [&](const TopicInfo& t) { return t.name == wanted; });
    if (it == topics.end() && listing_cut != nullptr) throw *listing_cut;
    if (it == topics.end())
      throw ReadError(path, -1, -1, "no topic '" + wanted + "' in the bag; its topics:" + topic_list(topics));
    if (message_kind(it->type) == MessageKind::not_events) {
      throw ReadError(path, -1, -1,
                      "topic '" + wanted + "' has type " + it->type +
                          ", not an event message (readable: " +
                          std::string(known_message_types()) + ")");
    }
    return of_one_type(path, *it);
  }
  std::vector<const TopicInfo*> events;
  for (const TopicInfo& t : topics)
    if (message_kind(t.type) != MessageKind::not_events) events.push_back(&t);
  if (events.size() == 1) return of_one_type(path, *events.front());
  if (events.empty() && listing_cut != nullptr) throw *listing_cut;
  if (events.empty()) {
    throw ReadError(path, -1, -1,
                    "no event topic in the bag (readable types: " +
                        std::string(known_message_types()) + "); its topics:" + topic_list(topics));
  }
  std::vector<TopicInfo> listed;
  for (const TopicInfo* t : events) listed.push_back(*t);
  throw ReadError(path, -1, -1, "several event topics: choose one with --topic NAME:" + topic_list(listed));
}

}  // namespace evlife::io::ros
