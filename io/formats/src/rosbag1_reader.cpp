// ROS 1 bags, format 2.0 (`#ROSBAG V2.0`): records = u32 header length,
// header fields (u32 length + "name=value"), u32 data length, data; `op` in
// the header: 0x03 bag header (index_pos), 0x05 chunk (compression none /
// bz2 / lz4, uncompressed size), 0x02 message data (conn, time), 0x07
// connection (conn, topic; data = type, md5sum, definition...), 0x04 index
// data, 0x06 chunk info (message counts per connection). The index after
// index_pos gives the topics without reading the chunks; messages are then
// streamed chunk by chunk in file order and decoded by ros::MessageDecoder
// in ROS 1 serialization (ros_messages.h: types, encodings, time rule) and
// delivered by ros::TopicEventReader (faults: ros_topic_reader.h).
// Without a usable index (a recording that stopped before closing its bag:
// index_pos 0 and the chunk being written still bearing its placeholder
// sizes; or an index cut short) the chunks are scanned for connections and
// counts, as `rosbag reindex` does, and the fault that ended the scan is
// raised after the events before it.
#include <bzlib.h>
#include <lz4frame.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <optional>

#include "cut_stream.h"
#include "hex_byte.h"
#include "input_file.h"
#include "reader_registry.h"
#include "ros_messages.h"  // EVLIFE_ROS_EVENT_MESSAGE_TYPES
#include "ros_topic_reader.h"
#include "ros_topics.h"

namespace evlife::io {
namespace {

constexpr std::string_view kRosbag1Magic = "#ROSBAG V2.0\n";
constexpr std::uint32_t kMaxRecordPart = 1u << 30;  // refuse absurd lengths

enum Op : std::uint8_t {
  kMessage = 0x02,
  kBagHeader = 0x03,
  kIndex = 0x04,
  kChunk = 0x05,
  kChunkInfo = 0x06,
  kConnection = 0x07
};

/// "name=value" fields of a record header.
using HeaderFields = std::map<std::string, std::string, std::less<>>;

bool parse_fields(std::span<const std::uint8_t> h, HeaderFields& fields) {
  fields.clear();
  std::size_t pos = 0;
  while (pos < h.size()) {
    std::uint32_t n = 0;
    if (h.size() - pos < 4) return false;
    std::memcpy(&n, h.data() + pos, 4);
    pos += 4;
    if (n > h.size() - pos) return false;
    const std::string_view f(reinterpret_cast<const char*>(h.data() + pos), n);
    pos += n;
    const std::size_t eq = f.find('=');
    if (eq == std::string_view::npos) return false;
    fields.emplace(std::string(f.substr(0, eq)), std::string(f.substr(eq + 1)));
  }
  return true;
}

template <typename T>
bool field(const HeaderFields& f, std::string_view name, T& v) {
  const auto it = f.find(name);
  if (it == f.end() || it->second.size() != sizeof(T)) return false;
  std::memcpy(&v, it->second.data(), sizeof(T));
  return true;
}

class Rosbag1Reader final : public ros::TopicEventReader {
 public:
  Rosbag1Reader(const std::string& path, const ReaderOptions& options) : file_(path) {
    std::array<std::byte, 13> magic{};
    if (file_.read_at(0, magic) != magic.size() ||
        std::memcmp(magic.data(), kRosbag1Magic.data(), kRosbag1Magic.size()) != 0)
      throw ReadError(path, 0, -1, "not a ROS 1 bag (no '#ROSBAG V2.0' line)");
    HeaderFields f;
    std::uint64_t data_at = 0;
    std::uint32_t data_len = 0;
    std::uint64_t next = read_record(kRosbag1Magic.size(), f, data_at, data_len);
    std::uint8_t op = 0;
    std::uint64_t index_pos = 0;
    if (!field(f, "op", op) || op != kBagHeader || !field(f, "index_pos", index_pos))
      throw ReadError(path, static_cast<std::int64_t>(kRosbag1Magic.size()), -1, "ROS 1 bag without its bag header record");
    first_record_ = next;
    // What the index must hold (rosbag writes both; a cut at a record boundary leaves fewer).
    has_counts_ = field(f, "conn_count", conn_count_) && field(f, "chunk_count", chunk_count_);
    const bool indexed = index_pos != 0 && index_pos < file_.size_bytes();
    if (indexed) {
      index_pos_ = index_pos;
      try {
        read_index();
        chunks_end_ = index_pos_;
        counts_from_index_ = true;
      } catch (const ros::ContainerFault& index_fault) {
        reading_index_ = false;
        scan_chunks(index_pos_, false);
        // The chunks read whole: the events are all there, the index is what was cut.
        if (!fault_) fault_ = index_fault;
      }
    } else {
      // index_pos 0: rosbag writes it when it closes the bag. Past the end: cut where the index began.
      scan_chunks(file_.size_bytes(), index_pos == 0);
      if (index_pos != 0 && !fault_) {
        fault_.emplace(path, static_cast<std::int64_t>(file_.size_bytes()),
                       "ROS 1 bag cut short: its index, at offset " + std::to_string(index_pos) +
                           ", is not in the file; the whole chunks before the cut were read");
        // Cut before index_pos: chunks are missing, so a topic may be too.
        scan_stopped_early_ = index_pos > file_.size_bytes();
      }
    }
    const ros::TopicInfo& topic = choose_topic(options.topic, index_pos == 0);
    for (const auto& [conn, c] : connections_)
      if (c.topic == topic.name) wanted_.push_back(conn);
    pos_ = first_record_;
    start(topics_, topic, ros::Serialization::ros1);
  }

  std::string_view format_name() const override { return "rosbag1"; }
  const std::string& path() const override { return file_.path(); }
  std::uint64_t bytes_consumed() const override { return pos_; }

 private:
  struct Connection {
    std::string topic;
    std::string type;
    std::uint64_t messages = 0;
    bool recorded = false;  // a connection record names it (else only a count or a message does)
    std::uint64_t delivered = 0;  // its messages next_in_chunks returned
  };

  /// A record of a chunk: its op, connection, data and where it begins.
  struct ChunkRecord {
    std::uint8_t op = 0;
    std::uint32_t conn = 0;
    bool has_conn = false;
    std::span<const std::uint8_t> data;
    std::size_t at = 0;  // byte of chunk_
  };

  /// ros::choose_topic, given the fault of a scan that stopped before the
  /// chunks' end (the topic's connection may lie beyond it).
  const ros::TopicInfo& choose_topic(const std::string& wanted, bool never_closed) {
    if (never_closed && connections_.empty() && !fault_)
      throw ReadError(file_.path(), static_cast<std::int64_t>(file_.size_bytes()), -1,
                      "ROS 1 bag of a recording that stopped before its first message reached the file (never "
                      "closed: index_pos 0, no message in its chunks)");
    return ros::choose_topic(file_.path(), topics_, wanted, scan_stopped_early_ && fault_ ? &*fault_ : nullptr);
  }

  [[noreturn]] void fail(std::uint64_t offset, const std::string& what) const {
    // In the index (past the chunks): a file cut there; its chunks are then scanned.
    throw ros::ContainerFault(file_.path(), static_cast<std::int64_t>(offset),
                              reading_index_ ? what + " (in the bag's index, after its chunks: a file cut short or corrupt; the "
                                                      "chunks were read without it)"
                                             : what);
  }

  /// Reads the record at `at`: its header fields and where its data is;
  /// returns the offset of the next record. Throws ReadError.
  std::uint64_t read_record(std::uint64_t at, HeaderFields& f, std::uint64_t& data_at, std::uint32_t& data_len) {
    std::uint32_t header_len = 0;
    if (file_.read_at(at, std::as_writable_bytes(std::span(&header_len, 1))) != 4)
      fail(at, "ROS 1 bag truncated inside a record header");
    if (header_len > kMaxRecordPart || header_len > file_.size_bytes() - at - 4)
      fail(at, "ROS 1 record header of " + std::to_string(header_len) + " bytes runs past the end of the file");
    header_.resize(header_len);
    if (file_.read_at(at + 4, std::as_writable_bytes(std::span(header_))) != header_len)
      fail(at, "ROS 1 bag truncated inside a record header");
    if (!parse_fields(header_, f)) fail(at, "corrupt ROS 1 record header");
    data_at = at + 4 + header_len;
    if (file_.read_at(data_at, std::as_writable_bytes(std::span(&data_len, 1))) != 4)
      fail(data_at, "ROS 1 bag truncated before a record's data length");
    data_at += 4;
    if (data_len > kMaxRecordPart || data_len > file_.size_bytes() - data_at)
      fail(data_at - 4, "ROS 1 record data of " + std::to_string(data_len) + " bytes runs past the end of the file");
    return data_at + data_len;
  }

  void read_data(std::uint64_t at, std::uint32_t len, std::vector<std::uint8_t>& out) {
    out.resize(len);
    if (file_.read_at(at, std::as_writable_bytes(std::span(out))) != len) fail(at, "ROS 1 bag truncated inside a record");
  }

  /// Connections and message counts from the index section.
  void read_index() {
    reading_index_ = true;
    HeaderFields f;
    HeaderFields conn_fields;
    std::vector<std::uint8_t> data;
    std::uint32_t connection_records = 0, chunk_infos = 0;
    for (std::uint64_t at = index_pos_; at < file_.size_bytes();) {
      std::uint64_t data_at = 0;
      std::uint32_t data_len = 0;
      const std::uint64_t next = read_record(at, f, data_at, data_len);
      std::uint8_t op = 0;
      field(f, "op", op);
      if (op == kConnection) {
        read_data(data_at, data_len, data);
        if (!add_connection(f, data)) fail(at, "corrupt ROS 1 connection record");
        ++connection_records;
      } else if (op == kChunkInfo) {
        ++chunk_infos;
        std::uint32_t count = 0;
        read_data(data_at, data_len, data);
        if (!field(f, "count", count) || data.size() < std::size_t{count} * 8) fail(at, "corrupt ROS 1 chunk info record");
        for (std::uint32_t i = 0; i < count; ++i) {
          std::uint32_t conn = 0, messages = 0;
          std::memcpy(&conn, data.data() + 8 * i, 4);
          std::memcpy(&messages, data.data() + 8 * i + 4, 4);
          connections_[conn].messages += messages;
        }
      }
      at = next;
    }
    if (has_counts_ && (connection_records < conn_count_ || chunk_infos < chunk_count_))
      fail(file_.size_bytes(), "ROS 1 bag index ends after " + std::to_string(connection_records) + " of its " +
                                   std::to_string(conn_count_) + " connection records and " + std::to_string(chunk_infos) +
                                   " of its " + std::to_string(chunk_count_) + " chunk infos");
    // A corrupt conn field would otherwise hide its messages (no topic names them).
    for (const auto& [conn, c] : connections_)
      if (!c.recorded)
        fail(index_pos_, "ROS 1 bag index counts " + std::to_string(c.messages) + " messages of connection " +
                             std::to_string(conn) + ", which none of its connection records names");
    reading_index_ = false;
    list_topics();
  }

  /// A connection record (header fields `f`, data `data`); false if corrupt.
  bool add_connection(const HeaderFields& f, std::span<const std::uint8_t> data) {
    std::uint32_t conn = 0;
    if (!field(f, "conn", conn) || !parse_fields(data, connection_fields_)) return false;
    Connection& c = connections_[conn];
    c.topic = f.count("topic") ? f.at("topic") : "";
    c.type = connection_fields_.count("type") ? connection_fields_.at("type") : "";
    c.recorded = true;
    return true;
  }

  void list_topics() {
    topics_.clear();
    std::map<std::string, std::size_t> by_topic;
    for (const auto& [id, c] : connections_) ros::add_topic(topics_, by_topic, ros::TopicInfo{c.topic, c.type, "ros1", c.messages, {}});
  }

  /// Connections and message counts from the chunks before `end` (no usable
  /// index). The first fault ends the scan: kept in fault_, raised after the
  /// events before it. `may_be_open`: the bag was never closed, so a chunk
  /// with placeholder sizes is the one being written when it stopped.
  void scan_chunks(std::uint64_t end, bool may_be_open) {
    connections_.clear();
    HeaderFields f;
    std::uint64_t at = first_record_;
    try {
      while (at < end) {
        std::uint64_t data_at = 0;
        std::uint32_t data_len = 0;
        const std::uint64_t next = read_record(at, f, data_at, data_len);
        std::uint8_t op = 0;
        std::uint32_t size = 0;
        check_top_level_op(at, f);
        if (field(f, "op", op) && op == kChunk) {
          if (may_be_open && data_len == 0 && field(f, "size", size) && size == 0) {
            scan_open_chunk(at, f, data_at);
            at = file_.size_bytes();
            break;
          }
          load_chunk(at, f, data_at, data_len);
          // Until its records all parse, the chunk a fault may stop the scan in:
          // what was counted of it is delivered.
          stopped_chunk_at_ = at;
          stopped_chunk_end_ = next;
          count_chunk_records(at, false);
          stopped_chunk_at_ = kNoChunk;
        }
        at = next;
      }
    } catch (const ros::ContainerFault& fault) {
      fault_ = fault;
      scan_stopped_early_ = true;
      if (at == stopped_chunk_at_) at = stopped_chunk_end_;  // its complete records are read
    }
    chunks_end_ = at;
    in_chunk_ = false;
    list_topics();
  }

  /// The chunk being written when the recording stopped (its header's sizes
  /// still placeholders): its records run to the file's end, the last maybe
  /// cut. The complete records are counted and read (stopped_chunk_bytes_ bytes
  /// of it); what follows them is the fault raised after their events.
  void scan_open_chunk(std::uint64_t at, const HeaderFields& f, std::uint64_t data_at) {
    stopped_chunk_at_ = at;
    stopped_chunk_end_ = file_.size_bytes();
    stopped_chunk_open_ = true;
    const OpenChunk open = load_open_chunk(at, f, data_at);
    const bool cut_record = count_chunk_records(at, true);
    if (!cut_record && !open.tail_left) return;
    if (open.compression == "none")
      fail(data_at + stopped_chunk_bytes_, "ROS 1 bag cut inside a record of the chunk being written when the recording "
                                       "stopped (" + std::to_string(open.bytes_on_disk - stopped_chunk_bytes_) +
                                       " bytes at this offset not read)");
    fail(at, "ROS 1 bag cut inside the chunk being written when the recording stopped (" + open.compression + ", " +
                 std::to_string(open.bytes_on_disk) + " bytes on disk): the records of its whole " + open.compression +
                 " blocks were read, the data after them is cut short");
  }

  struct OpenChunk {
    std::string compression;
    std::uint64_t bytes_on_disk = 0;
    bool tail_left = false;  // compressed bytes left that no whole block holds
  };

  /// chunk_ := the open chunk's records as far as they are on disk: its bytes,
  /// or what a streaming decoder makes of its bz2 / lz4 data cut short.
  OpenChunk load_open_chunk(std::uint64_t at, const HeaderFields& f, std::uint64_t data_at) {
    OpenChunk open;
    const auto compression = f.find("compression");
    open.compression = compression == f.end() ? std::string() : compression->second;
    open.bytes_on_disk = file_.size_bytes() - data_at;
    if (open.bytes_on_disk > kMaxRecordPart)
      fail(at, "ROS 1 chunk of " + std::to_string(open.bytes_on_disk) + " bytes (limit " + std::to_string(kMaxRecordPart) + ")");
    begin_chunk(at);
    if (open.compression == "none") {
      read_data(data_at, static_cast<std::uint32_t>(open.bytes_on_disk), chunk_);
      return open;
    }
    if (open.compression != "bz2" && open.compression != "lz4") refuse_compression(at, open.compression);
    read_data(data_at, static_cast<std::uint32_t>(open.bytes_on_disk), compressed_);
    open.tail_left = open.compression == "bz2" ? detail::inflate_cut_bz2(compressed_, chunk_, kMaxRecordPart)
                                                 : detail::inflate_cut_lz4(compressed_, chunk_, kMaxRecordPart);
    return open;
  }

  /// Counts the connections and messages of chunk_ (loaded from `chunk_at`);
  /// stopped_chunk_bytes_: the bytes of its whole records. A record that
  /// does not parse: with `cut_allowed` (the open chunk's last, cut by the
  /// stop) returns true, else throws; a corrupt connection record throws.
  bool count_chunk_records(std::uint64_t chunk_at, bool cut_allowed) {
    stopped_chunk_bytes_ = 0;
    ChunkRecord r;
    while (true) {
      try {
        if (!next_chunk_record(r)) return false;
      } catch (const ros::ContainerFault&) {
        if (!cut_allowed) throw;
        return true;
      }
      if (r.op == kConnection) {
        if (!add_connection(record_fields_, r.data)) fail(chunk_at, "corrupt ROS 1 connection record in the chunk at this offset");
      } else if (r.op == kMessage && r.has_conn) {
        ++connections_[r.conn].messages;
      }
      stopped_chunk_bytes_ = chunk_pos_;
    }
  }

  /// The next record of chunk_ (its header in record_fields_); false at its end.
  bool next_chunk_record(ChunkRecord& r) {
    if (chunk_pos_ >= chunk_.size()) return false;
    const std::size_t at = chunk_pos_;
    const auto bad = [&] { fail(chunk_at_, "corrupt record at byte " + std::to_string(at) + " of a ROS 1 chunk"); };
    std::uint32_t hlen = 0, dlen = 0;
    if (chunk_.size() - at < 4) bad();
    std::memcpy(&hlen, chunk_.data() + at, 4);
    if (hlen > chunk_.size() - at - 4 || chunk_.size() - at - 4 - hlen < 4) bad();
    if (!parse_fields(std::span(chunk_.data() + at + 4, hlen), record_fields_)) bad();
    std::memcpy(&dlen, chunk_.data() + at + 4 + hlen, 4);
    const std::size_t data = at + 8 + hlen;
    if (dlen > chunk_.size() - data) bad();
    chunk_pos_ = data + dlen;
    r.op = 0;
    r.has_conn = field(record_fields_, "conn", r.conn);
    // A chunk holds messages and connections, each naming its connection: a
    // record of another op, or none, was skipped with its messages, unsaid.
    if (!field(record_fields_, "op", r.op) || (r.op != kMessage && r.op != kConnection) || !r.has_conn)
      fail(chunk_at_, "corrupt record at byte " + std::to_string(at) + " of a ROS 1 chunk: " + op_text(record_fields_) +
                          (r.has_conn ? "" : ", no conn") + " (a chunk holds message 0x02 and connection 0x07 records)");
    r.data = std::span<const std::uint8_t>(chunk_.data() + data, dlen);
    r.at = at;
    return true;
  }

  /// Decompresses the chunk record at `at` into chunk_.
  void load_chunk(std::uint64_t at, const HeaderFields& f, std::uint64_t data_at, std::uint32_t data_len) {
    std::uint32_t size = 0;
    const auto compression = f.find("compression");
    if (compression == f.end() || !field(f, "size", size) || size > kMaxRecordPart)
      fail(at, "corrupt ROS 1 chunk header");
    read_data(data_at, data_len, compressed_);
    chunk_.resize(size);
    const std::string& kind = compression->second;
    bool ok = false;
    if (kind == "none") {
      ok = data_len == size;
      if (ok && size != 0) std::memcpy(chunk_.data(), compressed_.data(), size);  // empty vectors: null data()
    } else if (kind == "bz2") {
      unsigned int out_len = size;
      ok = BZ2_bzBuffToBuffDecompress(reinterpret_cast<char*>(chunk_.data()), &out_len,
                                      reinterpret_cast<char*>(compressed_.data()), data_len, 0, 0) == BZ_OK &&
           out_len == size;
    } else if (kind == "lz4") {
      LZ4F_dctx* ctx = nullptr;
      if (!LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION))) {
        std::size_t out_len = size;
        std::size_t in_len = data_len;
        const std::size_t r = LZ4F_decompress(ctx, chunk_.data(), &out_len, compressed_.data(), &in_len, nullptr);
        ok = !LZ4F_isError(r) && r == 0 && out_len == size;
        LZ4F_freeDecompressionContext(ctx);
      }
    } else {
      refuse_compression(at, kind);
    }
    if (!ok) fail(at, "corrupt ROS 1 chunk (" + kind + " data does not decompress to its " + std::to_string(size) + " bytes)");
    begin_chunk(at);
  }

  [[noreturn]] void refuse_compression(std::uint64_t chunk_at, const std::string& kind) const {
    fail(chunk_at, "ROS 1 chunk compressed with '" + kind + "' (readable: none, bz2, lz4)");
  }

  /// chunk_ (loaded from the chunk record at `at`) is read from its start.
  void begin_chunk(std::uint64_t at) {
    chunk_at_ = at;
    chunk_pos_ = 0;
    in_chunk_ = true;
  }

  /// The next message of the wanted topic: its data in `message`; false at
  /// the end. Where a scan stopped at a fault, the fault, once the events
  /// before it are out.
  bool next_in_chunks(std::span<const std::uint8_t>& message) {
    HeaderFields f;
    ChunkRecord r;
    while (true) {
      if (in_chunk_) {
        while (next_chunk_record(r)) {
          if (r.op != kMessage) continue;
          const auto c = connections_.find(r.conn);
          // A message no connection record names may be of the wanted topic (a corrupt conn field).
          if (c == connections_.end() || !c->second.recorded)
            fail(chunk_at_, "ROS 1 message of connection " + std::to_string(r.conn) +
                                ", which no connection record names (at byte " + std::to_string(r.at) +
                                " of the chunk at this offset)");
          if (std::find(wanted_.begin(), wanted_.end(), r.conn) != wanted_.end()) {
            ++c->second.delivered;
            message = r.data;
            return true;
          }
        }
        in_chunk_ = false;
      }
      if (pos_ >= chunks_end_) {
        if (fault_) {
          const ros::ContainerFault fault = *fault_;
          fault_.reset();
          throw fault;
        }
        if (counts_from_index_) check_index_counts();
        return false;
      }
      std::uint64_t data_at = 0;
      std::uint32_t data_len = 0;
      const std::uint64_t at = pos_;
      pos_ = read_record(at, f, data_at, data_len);
      if (at == stopped_chunk_at_) {
        if (stopped_chunk_open_) {
          load_open_chunk(at, f, data_at);
        } else {
          load_chunk(at, f, data_at, data_len);
        }
        chunk_.resize(stopped_chunk_bytes_);  // the records the scan counted
        pos_ = chunks_end_;
        continue;
      }
      check_top_level_op(at, f);
      std::uint8_t op = 0;
      if (field(f, "op", op) && op == kChunk) load_chunk(at, f, data_at, data_len);
    }
  }

  /// At the end of an indexed bag's chunks: each wanted connection delivered
  /// what its chunk infos count (a message whose conn was changed to another
  /// connection's is otherwise lost unsaid).
  void check_index_counts() {
    for (const std::uint32_t conn : wanted_) {
      const Connection& c = connections_.at(conn);
      if (c.delivered != c.messages)
        fail(index_pos_, "ROS 1 bag index counts " + std::to_string(c.messages) + " messages of connection " +
                             std::to_string(conn) + " (topic " + c.topic + "), its chunks hold " +
                             std::to_string(c.delivered));
    }
  }

  /// The records between the bag header and the index: chunks and their index
  /// data (connections and chunk infos where a writer puts them there); a
  /// record of another op, or none, was skipped with the messages it held.
  void check_top_level_op(std::uint64_t at, const HeaderFields& f) const {
    std::uint8_t op = 0;
    if (!field(f, "op", op) || (op != kChunk && op != kIndex && op != kConnection && op != kChunkInfo))
      fail(at, "corrupt ROS 1 record: " + op_text(f) + " where the chunks are (chunk 0x05, index data 0x04)");
  }

  static std::string op_text(const HeaderFields& f) {
    const auto it = f.find("op");
    if (it == f.end()) return "no op field";
    if (it->second.size() != 1) return "an op of " + std::to_string(it->second.size()) + " bytes";
    return "op " + detail::hex_byte(static_cast<std::uint8_t>(it->second[0]));
  }

  bool next_message(Message& m) override {
    std::span<const std::uint8_t> data;
    if (!next_in_chunks(data)) return false;
    m = Message{data, nullptr, static_cast<std::int64_t>(chunk_at_), " (in the chunk at this offset)"};
    return true;
  }

  detail::InputFile file_;
  std::map<std::uint32_t, Connection> connections_;
  std::vector<ros::TopicInfo> topics_;
  std::vector<std::uint32_t> wanted_;
  std::uint64_t first_record_ = 0;
  std::uint64_t index_pos_ = 0;
  bool scan_stopped_early_ = false;  // at fault_, before the chunks' end
  bool has_counts_ = false;  // the bag header's conn_count and chunk_count
  std::uint32_t conn_count_ = 0;
  std::uint32_t chunk_count_ = 0;
  std::uint64_t chunks_end_ = 0;  // where the chunks end: index_pos, or where a scan stopped
  std::optional<ros::ContainerFault> fault_;  // that stopped the scan; raised after the events before it
  // The chunk a scan stopped in (a record cut or corrupt), or the one being
  // written when a recording stopped: delivered up to its complete records.
  static constexpr std::uint64_t kNoChunk = std::numeric_limits<std::uint64_t>::max();
  std::uint64_t stopped_chunk_at_ = kNoChunk;
  std::uint64_t stopped_chunk_end_ = 0;  // where the next top-level record would be
  bool stopped_chunk_open_ = false;
  std::size_t stopped_chunk_bytes_ = 0;  // its complete records' bytes
  HeaderFields connection_fields_;
  HeaderFields record_fields_;
  bool reading_index_ = false;  // fail() says where a fault lies
  std::uint64_t pos_ = 0;  // next top-level record
  std::vector<std::uint8_t> header_;
  std::vector<std::uint8_t> compressed_;
  std::vector<std::uint8_t> chunk_;
  std::uint64_t chunk_at_ = 0;
  std::size_t chunk_pos_ = 0;
  bool in_chunk_ = false;
  bool counts_from_index_ = false;  // connections_' counts are the index's (else a scan's)
};

}  // namespace

namespace detail {
namespace {

SniffResult sniff_rosbag1(std::span<const std::byte> head, std::string_view path) {
  if (head.size() >= kRosbag1Magic.size() && std::memcmp(head.data(), kRosbag1Magic.data(), kRosbag1Magic.size()) == 0)
    return SniffResult::by_content;
  return has_extension(path, ".bag") ? SniffResult::by_extension : SniffResult::no;
}

std::unique_ptr<EventReader> open_rosbag1(const std::string& path, const ReaderOptions& options) {
  return std::make_unique<Rosbag1Reader>(path, options);
}

}  // namespace

const ReaderFormat rosbag1_format{
    "rosbag1",
    "ROS 1 bag v2.0 (.bag, or the .bag.active of an interrupted recording; chunks uncompressed, bz2 or lz4): "
    EVLIFE_ROS_EVENT_MESSAGE_TYPES,
    &sniff_rosbag1, nullptr, &open_rosbag1, nullptr, "topic"};

}  // namespace detail
}  // namespace evlife::io
