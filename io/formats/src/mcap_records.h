// Private: the records of an MCAP file (https://mcap.dev/spec, major version
// 0), parsed from bytes already in memory. Everything little-endian; a string
// is u32 length + UTF-8 bytes; a map is u32 byte length + entries. A record is
// u8 opcode + u64 content length + content. File layout:
//   magic "\x89MCAP0\r\n", Header, data section (Schema, Channel, Message,
//   Chunk, MessageIndex, Attachment, Metadata, ..., DataEnd), optional summary
//   and summary-offset sections, Footer, magic.
// The parsers return false when the content is shorter than its fields;
// fields added by later minor versions (extra bytes at the end) are ignored.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace evlife::io::mcap {

inline constexpr std::uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
inline constexpr std::size_t kRecordPrefix = 9;  // opcode + content length
inline constexpr std::size_t kFooterContent = 20;

enum Op : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kAttachment = 0x09,
  kAttachmentIndex = 0x0A,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

struct Footer {
  std::uint64_t summary_start = 0;  ///< 0: no summary section
  std::uint64_t summary_offset_start = 0;
  std::uint32_t summary_crc = 0;
};

struct Schema {
  std::uint16_t id = 0;
  std::string name;      ///< the message type, e.g. "dvs_msgs/msg/EventArray"
  std::string encoding;  ///< "ros2msg", "ros2idl", ...
};

struct Channel {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;  ///< 0: no schema
  std::string topic;
  std::string message_encoding;  ///< "cdr" for ROS 2
};

struct Message {
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time = 0;  ///< ns
  std::uint64_t publish_time = 0;
  std::span<const std::uint8_t> data;  ///< the serialized message
};

struct Chunk {
  std::uint64_t message_start_time = 0;
  std::uint64_t message_end_time = 0;
  std::uint64_t uncompressed_size = 0;
  std::uint32_t uncompressed_crc = 0;  ///< CRC-32 of the records; 0 = not given
  std::string compression;             ///< "", "zstd" or "lz4" (LZ4 frame format)
  std::span<const std::uint8_t> records;
};

bool parse_footer(std::span<const std::uint8_t> content, Footer& f);
bool parse_schema(std::span<const std::uint8_t> content, Schema& s);
bool parse_channel(std::span<const std::uint8_t> content, Channel& c);
bool parse_message(std::span<const std::uint8_t> content, Message& m);
/// The fixed fields and the compressed records; `records` spans into `content`.
bool parse_chunk(std::span<const std::uint8_t> content, Chunk& c);
/// Statistics: the message count of each channel id.
bool parse_statistics(std::span<const std::uint8_t> content, std::map<std::uint16_t, std::uint64_t>& counts);

/// One record inside a byte range (a decompressed chunk, the summary).
struct Record {
  std::uint8_t op = 0;
  std::span<const std::uint8_t> content;
};
/// The record at `pos` of `bytes`; nullopt when its prefix or content runs past the end.
std::optional<Record> record_at(std::span<const std::uint8_t> bytes, std::size_t pos);

/// Decompresses a chunk's records into `out` (resized to uncompressed_size)
/// and checks the CRC when given. Returns what is wrong, or nullopt. A zstd
/// or lz4 chunk may hold several concatenated frames (and skippable frames).
std::optional<std::string> decompress_chunk(const Chunk& c, std::vector<std::uint8_t>& out);

/// The CRC-32 (zlib's, as MCAP uses) of `bytes` continued from `crc` (0 to start).
std::uint32_t crc32_update(std::uint32_t crc, std::span<const std::uint8_t> bytes);

/// The record sizes of the CRC-checked ends of a file: DataEnd (u32 data
/// section CRC: of every byte from the file's start to the DataEnd record;
/// 0 = not given) and the Footer's fields the summary CRC covers (from the
/// summary's start through summary_offset_start; 0 = not given).
inline constexpr std::size_t kDataEndContent = 4;
inline constexpr std::size_t kFooterCrcCovered = kRecordPrefix + 16;

}  // namespace evlife::io::mcap
