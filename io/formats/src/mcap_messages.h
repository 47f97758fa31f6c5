// Private: the messages of one topic of an MCAP file, streamed with bounded
// memory (one chunk at a time). Topics, types and message counts come from
// the summary section (Channel, Schema, Statistics records) when the file has
// one; otherwise (no summary, no statistics, or a truncated file) from a scan
// of the data section at open that stops quietly at the first fault, which
// next() reports in its turn.
// CRCs: a chunk's records CRC (when non-zero) as each chunk is read; the
// DataEnd record's data-section CRC (when non-zero) as the stream reaches it,
// over every byte read before it; the Footer's summary CRC (when non-zero) at
// open: on a mismatch the summary is not used (the data section is scanned)
// and the fault is raised at the end of the stream. Each fault names the file
// and the byte offset of the record at fault; the events before it are kept.
// ORDER: chunks and unchunked messages in file order (writers append chunks
// as time advances); inside a chunk, the topic's messages in log-time order
// (stable sort). Overlapping chunks are not merged: events that then go
// backwards stop the read with the reader's time-order error.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <vector>

#include "evlife/io/event_reader.h"
#include "input_file.h"
#include "mcap_records.h"
#include "ros_topic_reader.h"  // ros::ContainerFault
#include "rosbag2_messages.h"  // ros::TopicInfo

namespace evlife::io::mcap {


class McapMessages {
 public:
  /// Opens the file, checks the magic and Header, reads the topics; throws ReadError.
  explicit McapMessages(const std::string& path);

  /// Every topic (type = its schema name, serialization = message encoding).
  const std::vector<ros::TopicInfo>& topics() const noexcept { return topics_; }
  /// The fault that stopped the scan of the data section at open (topics
  /// listed from it), if any: where the topic asked for, or any event topic,
  /// is missing, the file may be cut before it (ros::choose_topic).
  const ReadError* listing_fault() const noexcept { return scan_fault_ ? &*scan_fault_ : nullptr; }

  /// Starts streaming the messages of topic `name` from the data section's start.
  void select(const std::string& name);

  struct Message {
    std::span<const std::uint8_t> data;  ///< valid until the next next()
    std::uint64_t log_time_ns = 0;
    std::uint64_t index = 0;      ///< 0-based index among the topic's messages
    std::uint64_t record_at = 0;  ///< file offset of its Chunk (or Message) record
  };
  /// The next message of the selected topic; false at the end. Throws
  /// ros::ContainerFault (truncation, corrupt chunk or record, unknown compression).
  bool next(Message& m);

  /// Records of unknown opcodes (0x00, 0x10-0x7F reserved, 0x80-0xFF private)
  /// the stream skipped, as the specification says: a Chunk or Message whose
  /// opcode was damaged is among them.
  std::uint64_t unknown_records_skipped() const noexcept { return unknown_skipped_; }
  /// File offset reached by the stream.
  std::uint64_t bytes_consumed() const noexcept { return pos_; }
  const std::string& path() const noexcept { return file_.path(); }

 private:
  /// A top-level data-section record read into memory (Chunks decompressed).
  struct Unit {
    std::uint8_t op = 0;
    std::uint64_t at = 0;                   ///< file offset of the record
    std::span<const std::uint8_t> content;  ///< a chunk's decompressed records
  };
  /// The next unit from `pos`; false at DataEnd / the summary / the Footer.
  /// With `crc`: every byte passed is added to it, and a non-zero DataEnd
  /// CRC is checked against it.
  bool next_unit(std::uint64_t& pos, Unit& u, std::uint32_t* crc = nullptr);
  /// `crc` continued over the file's bytes [from, to).
  std::uint32_t crc_of_file(std::uint64_t from, std::uint64_t to, std::uint32_t crc);
  /// False when the Footer states a summary CRC that the bytes do not match.
  bool summary_crc_matches(const Footer& footer, std::uint64_t footer_at);
  [[noreturn]] void fail(std::uint64_t at, const std::string& what) const;
  void read_summary(const Footer& footer, std::uint64_t footer_at);
  void scan_data_section();
  /// Schema and Channel records (wherever found); false if malformed, or if
  /// it redefines a known id otherwise (the spec forbids it: the messages of
  /// one id went to another topic, unsaid), said in learn_fault_.
  bool learn(const Record& r);
  /// What learn() found wrong, after ": " (empty: malformed).
  std::string learn_fault() const { return learn_fault_.empty() ? std::string() : ": " + learn_fault_; }
  void build_topics(const std::map<std::uint16_t, std::uint64_t>& counts);
  void load_chunk(const Unit& u);
  bool wanted(std::uint16_t channel_id) const;
  /// At the stream's end: the topic's messages as many as the summary's
  /// Statistics record counts (where it counts each of the topic's channels).
  void check_statistics_count() const;

  detail::InputFile file_;
  std::uint64_t data_start_ = 0;
  std::uint64_t data_limit_ = 0;  ///< summary start or Footer offset; else the file size
  bool has_footer_ = false;
  std::map<std::uint16_t, Schema> schemas_;
  std::map<std::uint16_t, Channel> channels_;
  std::string learn_fault_;
  std::vector<ros::TopicInfo> topics_;
  std::string topic_;
  bool selected_ = false;
  std::uint64_t pos_ = 0;
  bool ended_ = false;
  std::vector<std::uint8_t> record_;  ///< the current top-level record's content
  std::vector<std::uint8_t> chunk_;   ///< the current chunk, decompressed
  struct Pending {
    std::uint64_t log_time_ns;
    std::size_t at;  ///< offset of the Message record's content in chunk_
    std::size_t size;
  };
  std::vector<Pending> pending_;  ///< the topic's messages of the current chunk, sorted
  std::size_t pending_next_ = 0;
  std::uint64_t chunk_at_ = 0;
  std::optional<ros::ContainerFault> chunk_fault_;  ///< raised once pending_ is delivered
  std::optional<ros::ContainerFault> summary_fault_;  ///< raised at the end of the stream
  std::optional<ReadError> scan_fault_;  ///< the fault that stopped scan_data_section()
  bool data_crc_wanted_ = true;  ///< false when the DataEnd found at open says 0
  std::uint32_t data_crc_ = 0;   ///< of the bytes streamed so far
  std::vector<std::uint8_t> scratch_;  ///< for CRCs of records not otherwise read
  std::uint64_t next_index_ = 0;
  std::uint64_t unknown_skipped_ = 0;
  std::set<std::uint16_t> counted_channels_;  ///< the channels the summary's Statistics count
};

/// True when `head` starts with the MCAP magic.
bool has_magic(std::span<const std::byte> head);

}  // namespace evlife::io::mcap
