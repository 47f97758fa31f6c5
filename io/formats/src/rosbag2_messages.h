// Private: the messages of a ROS 2 bag stored with the sqlite3 plugin
// (rosbag2 "storage_identifier: sqlite3"): a `.db3` file, or the bag folder
// (metadata.yaml lists its .db3 files in `relative_file_paths`, read in that
// order; without metadata.yaml, every *.db3 in name order). Tables used:
// topics(id, name, type, serialization_format) and messages(id, topic_id,
// timestamp, data). One topic's messages stream in (timestamp, id) order.
// Messages compressed one by one (a bag recorded with --compression-mode
// message: each a zstd frame) are decompressed; so are the files of a bag
// recorded with --compression-mode file (NAME.db3.zstd), each into a
// temporary copy for SQLite, one file at a time (zstd_temp_copy.h). A later
// file of a split bag that cannot be read is a fault raised after the
// messages of the files before it (deferred_fault()).
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "evlife/io/event_reader.h"

namespace evlife::io::detail {
class ZstdTempCopy;  // zstd_temp_copy.h
}  // namespace evlife::io::detail

namespace evlife::io::ros {

struct TopicInfo {
  std::string name;
  std::string type;
  std::string serialization;
  std::uint64_t message_count = 0;
  std::string other_type;  ///< a second message type on the same topic (another connection or channel)
};

class Rosbag2Messages {
 public:
  /// Opens a .db3 file or a bag folder; throws ReadError.
  explicit Rosbag2Messages(const std::string& path);
  ~Rosbag2Messages();
  Rosbag2Messages(const Rosbag2Messages&) = delete;
  Rosbag2Messages& operator=(const Rosbag2Messages&) = delete;

  /// Every topic of the bag (over all its files), with message counts.
  const std::vector<TopicInfo>& topics() const noexcept { return topics_; }
  /// Messages whose topic_id no topics row lists (a damaged bag): no topic's,
  /// never read, counted for `evlife info`.
  std::uint64_t unlisted_message_count() const noexcept { return unlisted_messages_; }

  /// Messages of the selected topic that metadata.yaml counts and no file
  /// holds (beyond those unlisted_message_count() may be).
  std::uint64_t missing_message_count() const noexcept { return missing_messages_; }

  /// Starts streaming the messages of topic `name` (from the first file).
  void select(const std::string& name);

  struct Message {
    std::span<const std::uint8_t> data;  ///< valid until the next next()
    std::int64_t bag_time_ns = 0;         ///< receive time stored by the recorder
    std::uint64_t index = 0;              ///< 0-based index among the topic's messages
    const std::string* file = nullptr;    ///< the .db3 it comes from
  };
  /// The next message of the selected topic; false at the end. Throws ReadError.
  bool next(Message& m);

  /// The .db3 (or .db3.zstd) files, in reading order.
  const std::vector<std::string>& files() const noexcept { return files_; }
  /// The fault of a later file whose topics could not be read, raised by
  /// next() after the earlier files' messages (none: nullptr).
  const ReadError* deferred_fault() const noexcept { return fault_ ? &*fault_ : nullptr; }

 private:
  struct Db;
  void read_topics(std::size_t i, std::map<std::string, std::size_t>& by_name);
  /// File i's decompressed copy if it is a .db3.zstd, else nullptr.
  std::shared_ptr<const detail::ZstdTempCopy> copy_of(std::size_t i) const;
  void open_file(std::size_t i);
  /// rosbag2's message compression (compression_mode: message): the zstd
  /// `frame` decompressed into inflated_. Throws ReadError.
  std::span<const std::uint8_t> inflate(std::span<const std::uint8_t> frame);

  std::vector<std::string> files_;
  std::shared_ptr<const detail::ZstdTempCopy> copy_;  // of the file being read, if compressed
  std::optional<ReadError> fault_;  // of a later file, raised after the files before it
  std::vector<TopicInfo> topics_;
  std::map<std::string, std::uint64_t> metadata_counts_;  // metadata.yaml's messages by topic (none: empty)
  std::uint64_t missing_messages_ = 0;
  std::uint64_t unlisted_messages_ = 0;
  std::unique_ptr<Db> db_;
  std::size_t file_index_ = 0;
  std::string topic_;
  std::uint64_t next_index_ = 0;
  bool selected_ = false;
  std::vector<std::uint8_t> inflated_;  // the last message, decompressed
};

/// True when `path` is a directory holding a rosbag2 sqlite3 bag
/// (metadata.yaml, *.db3 or *.db3.zstd files).
bool is_rosbag2_directory(const std::string& path);
/// True for data starting with a zstd frame's magic: a message compressed
/// by rosbag2, or a file-compressed bag's NAME.db3.zstd (the only whole-file
/// zstd evlife reads).
bool is_zstd_stream(std::span<const std::byte> head);

}  // namespace evlife::io::ros
