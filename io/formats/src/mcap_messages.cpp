#include "mcap_messages.h"

#include <algorithm>
#include <array>
#include <cstring>

#include "evlife/io/event_reader.h"
#include "hex_byte.h"
#include "ros_topics.h"

namespace evlife::io::mcap {
namespace {

/// 0x00 and the opcodes past DataEnd (reserved for later versions, or private).
bool is_unknown_op(std::uint8_t op) { return op == 0x00 || op > kDataEnd; }

constexpr std::uint64_t kMaxRecordBytes = std::uint64_t{1} << 28;   // one message or chunk
constexpr std::uint64_t kMaxSummaryBytes = std::uint64_t{1} << 26;  // else: scan instead
constexpr std::uint64_t kFooterRecord = kRecordPrefix + kFooterContent;


}  // namespace

bool has_magic(std::span<const std::byte> head) {
  return head.size() >= sizeof(kMagic) && std::memcmp(head.data(), kMagic, sizeof(kMagic)) == 0;
}

void McapMessages::fail(std::uint64_t at, const std::string& what) const {
  throw ros::ContainerFault(file_.path(), static_cast<std::int64_t>(at), what);
}

McapMessages::McapMessages(const std::string& path) : file_(path) {
  const std::uint64_t size = file_.size_bytes();
  std::array<std::uint8_t, sizeof(kMagic) + kRecordPrefix> head{};
  const std::size_t got = file_.read_at(0, std::as_writable_bytes(std::span(head)));
  if (got < sizeof(kMagic) || std::memcmp(head.data(), kMagic, sizeof(kMagic)) != 0)
    fail(0, "not an MCAP file (no '\\x89MCAP0\\r\\n' magic)");
  if (got != head.size()) fail(sizeof(kMagic), "MCAP file truncated inside its Header record");
  std::uint64_t header_len = 0;
  std::memcpy(&header_len, head.data() + sizeof(kMagic) + 1, 8);
  if (head[sizeof(kMagic)] != kHeader) fail(sizeof(kMagic), "MCAP file without its Header record");
  if (header_len > size - head.size())
    fail(sizeof(kMagic), "MCAP file truncated inside its Header record");
  data_start_ = head.size() + header_len;
  data_limit_ = size;
  // Footer + trailing magic: present in every complete file.
  std::array<std::uint8_t, kFooterRecord + sizeof(kMagic)> tail{};
  if (size >= data_start_ + tail.size() &&
      file_.read_at(size - tail.size(), std::as_writable_bytes(std::span(tail))) == tail.size() &&
      std::memcmp(tail.data() + kFooterRecord, kMagic, sizeof(kMagic)) == 0 && tail[0] == kFooter) {
    std::uint64_t len = 0;
    std::memcpy(&len, tail.data() + 1, 8);
    Footer footer;
    const std::uint64_t footer_at = size - tail.size();
    if (len == kFooterContent && parse_footer(std::span(tail).subspan(kRecordPrefix, kFooterContent), footer)) {
      has_footer_ = true;
      data_limit_ = footer_at;
      const bool summary_ok = summary_crc_matches(footer, footer_at);
      if (footer.summary_start >= data_start_ && footer.summary_start < footer_at) {
        data_limit_ = footer.summary_start;
        if (summary_ok) read_summary(footer, footer_at);
      }
    }
  }
  // The DataEnd record ends the data section: no CRC to compute when it says 0.
  std::array<std::uint8_t, kRecordPrefix + kDataEndContent> end{};
  if (has_footer_ && data_limit_ >= data_start_ + end.size() &&
      file_.read_at(data_limit_ - end.size(), std::as_writable_bytes(std::span(end))) == end.size() &&
      end[0] == kDataEnd) {
    std::uint64_t len = 0;
    std::uint32_t crc = 0;
    std::memcpy(&len, end.data() + 1, 8);
    std::memcpy(&crc, end.data() + kRecordPrefix, 4);
    if (len == kDataEndContent && crc == 0) data_crc_wanted_ = false;
  }
  if (topics_.empty()) scan_data_section();
}

std::uint32_t McapMessages::crc_of_file(std::uint64_t from, std::uint64_t to, std::uint32_t crc) {
  scratch_.resize(1 << 16);
  while (from < to) {
    const std::size_t k = static_cast<std::size_t>(std::min<std::uint64_t>(to - from, scratch_.size()));
    const auto piece = std::span(scratch_).first(k);
    if (file_.read_at(from, std::as_writable_bytes(piece)) != k) fail(from, "MCAP file truncated");
    crc = crc32_update(crc, piece);
    from += k;
  }
  return crc;
}

bool McapMessages::summary_crc_matches(const Footer& footer, std::uint64_t footer_at) {
  if (footer.summary_crc == 0) return true;
  // From the summary's start (the Footer's when there is none) through the
  // Footer's summary_offset_start field.
  const std::uint64_t from = footer.summary_start != 0 ? footer.summary_start : footer_at;
  if (from < data_start_ || from > footer_at) return true;  // no summary to trust anyway
  const std::uint32_t crc = crc_of_file(from, footer_at + kFooterCrcCovered, 0);
  if (crc == footer.summary_crc) return true;
  summary_fault_.emplace(file_.path(), static_cast<std::int64_t>(from),
                         "MCAP summary CRC mismatch (CRC-32 of bytes " + std::to_string(from) + ".." +
                             std::to_string(footer_at + kFooterCrcCovered) + " is " + std::to_string(crc) +
                             ", the Footer says " + std::to_string(footer.summary_crc) +
                             "): the summary section at this offset is corrupt; its topics and counts "
                             "were not used");
  return false;
}

void McapMessages::read_summary(const Footer& footer, std::uint64_t footer_at) {
  std::uint64_t end = footer_at;
  if (footer.summary_offset_start > footer.summary_start && footer.summary_offset_start <= footer_at)
    end = footer.summary_offset_start;
  if (end - footer.summary_start > kMaxSummaryBytes) return;
  std::vector<std::uint8_t> summary(static_cast<std::size_t>(end - footer.summary_start));
  if (file_.read_at(footer.summary_start, std::as_writable_bytes(std::span(summary))) != summary.size()) return;
  std::map<std::uint16_t, std::uint64_t> counts;
  bool has_statistics = false;
  for (std::size_t pos = 0; pos < summary.size();) {
    const std::optional<Record> r = record_at(summary, pos);
    if (!r) return;  // a corrupt summary: the scan decides
    if (r->op == kStatistics) {
      if (!parse_statistics(r->content, counts)) return;
      // An empty map: "this statistic is not available" (the spec); the scan counts.
      has_statistics = !counts.empty();
    } else if (!learn(*r)) {
      return;
    }
    pos += kRecordPrefix + r->content.size();
  }
  if (has_statistics && !channels_.empty()) {
    build_topics(counts);
    for (const auto& [id, n] : counts) counted_channels_.insert(id);
  }
}

void McapMessages::check_statistics_count() const {
  // Only where the Statistics count every channel of the topic (a channel it leaves out: unknown).
  bool counted = !counted_channels_.empty();
  for (const auto& [id, c] : channels_)
    if (c.topic == topic_ && !counted_channels_.count(id)) counted = false;
  if (!counted) return;
  for (const ros::TopicInfo& t : topics_)
    if (t.name == topic_ && t.message_count != next_index_)
      fail(pos_, "MCAP summary's Statistics count " + std::to_string(t.message_count) + " messages on topic " + topic_ +
                     ", the data section holds " + std::to_string(next_index_) + " (records lost to a corruption?)");
}

void McapMessages::scan_data_section() {
  std::map<std::uint16_t, std::uint64_t> counts;
  const auto visit = [&](const Record& r) {
    mcap::Message m;
    if (r.op == kMessage && parse_message(r.content, m)) ++counts[m.channel_id];
    return learn(r);
  };
  try {
    std::uint64_t pos = data_start_;
    Unit u;
    // A record it cannot parse stops the scan as a fault does (said where its topics are missing).
    const auto stopped_at = [&](std::uint64_t at, const char* what) {
      scan_fault_.emplace(file_.path(), static_cast<std::int64_t>(at), -1,
                          std::string("corrupt MCAP ") + what + " at this offset (the topics were listed up to it)");
    };
    while (next_unit(pos, u)) {
      if (u.op != kChunk) {
        if (!visit(Record{u.op, u.content})) {
          stopped_at(u.at, ("record" + learn_fault()).c_str());
          break;
        }
        continue;
      }
      bool ok = true;
      for (std::size_t at = 0; ok && at < u.content.size();) {
        const std::optional<Record> r = record_at(u.content, at);
        ok = r && visit(*r);
        if (r) at += kRecordPrefix + r->content.size();
      }
      if (!ok) {
        stopped_at(u.at, ("record in the chunk" + learn_fault()).c_str());
        break;
      }
    }
  } catch (const ReadError& e) {
    // the stream reports the fault when it gets there, after the events before it; where the
    // topics it stopped short of are asked for, opening reports it (listing_fault())
    scan_fault_.emplace(e);
  }
  build_topics(counts);
}

bool McapMessages::learn(const Record& r) {
  learn_fault_.clear();
  if (r.op == kSchema) {
    Schema s;
    if (!parse_schema(r.content, s)) return false;
    if (s.id == 0) return true;
    if (const auto known = schemas_.find(s.id);
        known != schemas_.end() && known->second.name != s.name) {  // (mcap convert: one name, two encodings)
      learn_fault_ = "Schema " + std::to_string(s.id) + " redefined as '" + s.name + "', it was '" +
                     known->second.name + "' (one id, one schema)";
      return false;
    }
    schemas_[s.id] = std::move(s);
  } else if (r.op == kChannel) {
    Channel c;
    if (!parse_channel(r.content, c)) return false;
    if (const auto known = channels_.find(c.id);
        known != channels_.end() && (known->second.topic != c.topic || known->second.schema_id != c.schema_id)) {
      learn_fault_ = "Channel " + std::to_string(c.id) + " redefined as topic '" + c.topic + "' (schema " +
                     std::to_string(c.schema_id) + "), it was '" + known->second.topic + "' (schema " +
                     std::to_string(known->second.schema_id) + "): one id, one channel";
      return false;
    }
    channels_[c.id] = std::move(c);
  }
  return true;
}

void McapMessages::build_topics(const std::map<std::uint16_t, std::uint64_t>& counts) {
  topics_.clear();
  std::map<std::string, std::size_t> by_name;
  for (const auto& [id, c] : channels_) {
    const auto schema = schemas_.find(c.schema_id);
    const auto count = counts.find(id);
    const std::uint64_t n = count != counts.end() ? count->second : 0;
    ros::add_topic(topics_, by_name,
                   ros::TopicInfo{c.topic, schema != schemas_.end() ? schema->second.name : "", c.message_encoding, n, {}});
  }
}

bool McapMessages::next_unit(std::uint64_t& pos, Unit& u, std::uint32_t* crc) {
  if (pos >= data_limit_) {
    if (!has_footer_) fail(pos, "MCAP file ends without its DataEnd and Footer records (truncated)");
    return false;
  }
  std::array<std::uint8_t, kRecordPrefix> prefix{};
  if (data_limit_ - pos < kRecordPrefix ||
      file_.read_at(pos, std::as_writable_bytes(std::span(prefix))) != prefix.size())
    fail(pos, has_footer_ ? "MCAP record header runs past the data section" : "MCAP file truncated inside a record header");
  std::uint64_t len = 0;
  std::memcpy(&len, prefix.data() + 1, 8);
  u.op = prefix[0];
  u.at = pos;
  u.content = {};
  if (len > data_limit_ - pos - kRecordPrefix)
    fail(pos, "MCAP record (opcode " + detail::hex_byte(u.op) + ") of " + std::to_string(len) + " bytes runs past the " +
                  (has_footer_ ? "data section" : "end of the file (truncated)"));
  if (u.op == kDataEnd && crc != nullptr) {
    std::array<std::uint8_t, kDataEndContent> content{};
    if (len < content.size() ||
        file_.read_at(pos + kRecordPrefix, std::as_writable_bytes(std::span(content))) != content.size())
      fail(u.at, "corrupt MCAP DataEnd record");
    std::uint32_t expected = 0;
    std::memcpy(&expected, content.data(), 4);
    if (expected != 0 && expected != *crc)
      fail(u.at, "MCAP data section CRC mismatch (CRC-32 of bytes 0.." + std::to_string(u.at) + " is " +
                     std::to_string(*crc) + ", the DataEnd record at this offset says " +
                     std::to_string(expected) + "): the data section is corrupt");
  }
  pos += kRecordPrefix + len;
  // A Footer is the file's last record; DataEnd ends the data section where the
  // Footer says (a chunk's opcode damaged into one ended the read there, unsaid).
  if (u.op == kFooter || (u.op == kDataEnd && has_footer_ && pos != data_limit_))
    fail(u.at, "MCAP " + std::string(u.op == kFooter ? "Footer" : "DataEnd") + " record inside the data section, " +
                   std::to_string(data_limit_ - pos) + " bytes before its end (a corrupt opcode?)");
  if (u.op == kDataEnd) return false;
  // A second Header is no record of the data section. Unknown opcodes (0x00,
  // 0x10-0x7F reserved for later versions, 0x80-0xFF private) are skipped, as
  // the specification says, and next() counts them: a damaged opcode hides a
  // Chunk or Message that way.
  if (u.op == kHeader) fail(u.at, "corrupt MCAP record: a second Header in the data section");
  if (u.op != kSchema && u.op != kChannel && u.op != kMessage && u.op != kChunk) {  // skipped
    if (crc != nullptr) *crc = crc_of_file(u.at, pos, *crc);
    return true;
  }
  if (len > kMaxRecordBytes)
    fail(u.at, "MCAP record of " + std::to_string(len) + " bytes, over this reader's limit");
  record_.resize(static_cast<std::size_t>(len));
  if (file_.read_at(u.at + kRecordPrefix, std::as_writable_bytes(std::span(record_))) != record_.size())
    fail(u.at, "MCAP file truncated inside a record");
  if (crc != nullptr) *crc = crc32_update(crc32_update(*crc, prefix), record_);
  u.content = record_;
  if (u.op == kChunk) {
    Chunk c;
    if (!parse_chunk(record_, c)) fail(u.at, "corrupt MCAP chunk header");
    if (const std::optional<std::string> bad = decompress_chunk(c, chunk_)) fail(u.at, "MCAP " + *bad);
    u.content = chunk_;
  }
  return true;
}

void McapMessages::select(const std::string& name) {
  topic_ = name;
  selected_ = true;
  ended_ = false;
  pos_ = data_start_;
  pending_.clear();
  pending_next_ = 0;
  chunk_fault_.reset();
  next_index_ = 0;
  unknown_skipped_ = 0;
  if (data_crc_wanted_) data_crc_ = crc_of_file(0, data_start_, 0);  // magic and Header
}

bool McapMessages::wanted(std::uint16_t channel_id) const {
  const auto c = channels_.find(channel_id);
  return c != channels_.end() && c->second.topic == topic_;
}

void McapMessages::load_chunk(const Unit& u) {
  pending_.clear();
  pending_next_ = 0;
  chunk_at_ = u.at;
  for (std::size_t at = 0; at < u.content.size();) {
    const std::optional<Record> r = record_at(u.content, at);
    mcap::Message m;
    if (r && is_unknown_op(r->op)) {  // skipped and counted, as at the top level
      ++unknown_skipped_;
      at += kRecordPrefix + r->content.size();
      continue;
    }
    // A chunk holds Schema, Channel and Message records (another known opcode hid a Message).
    if (!r || (r->op != kSchema && r->op != kChannel && r->op != kMessage) || !learn(*r) ||
        (r->op == kMessage && !parse_message(r->content, m))) {
      // Deliver the chunk's messages before the fault first.
      chunk_fault_.emplace(file_.path(), static_cast<std::int64_t>(u.at),
                           "corrupt record at byte " + std::to_string(at) + " of the MCAP chunk at this offset" +
                               (r ? learn_fault() : std::string()));
      break;
    }
    if (r->op == kMessage && !channels_.count(m.channel_id)) {
      chunk_fault_.emplace(file_.path(), static_cast<std::int64_t>(u.at),
                           "MCAP Message at byte " + std::to_string(at) + " of the chunk at this offset is on channel " +
                               std::to_string(m.channel_id) + ", which no Channel record defines before it");
      break;
    }
    if (r->op == kMessage && wanted(m.channel_id)) {
      pending_.push_back(Pending{m.log_time, static_cast<std::size_t>(r->content.data() - chunk_.data()),
                                 r->content.size()});
    }
    at += kRecordPrefix + r->content.size();
  }
  std::stable_sort(pending_.begin(), pending_.end(),
                   [](const Pending& a, const Pending& b) { return a.log_time_ns < b.log_time_ns; });
}

bool McapMessages::next(Message& m) {
  if (!selected_ || ended_) return false;
  while (true) {
    if (pending_next_ < pending_.size()) {
      const Pending& p = pending_[pending_next_++];
      mcap::Message msg;
      parse_message(std::span<const std::uint8_t>(chunk_).subspan(p.at, p.size), msg);
      m = Message{msg.data, msg.log_time, next_index_++, chunk_at_};
      return true;
    }
    if (chunk_fault_) throw *chunk_fault_;
    Unit u;
    if (!next_unit(pos_, u, data_crc_wanted_ ? &data_crc_ : nullptr)) {
      ended_ = true;
      if (summary_fault_) throw *summary_fault_;  // after every event
      check_statistics_count();
      return false;
    }
    if (u.op == kChunk) {
      load_chunk(u);
    } else if (u.op == kSchema || u.op == kChannel) {
      if (!learn(Record{u.op, u.content}))
        fail(u.at, "corrupt MCAP " + std::string(u.op == kSchema ? "Schema" : "Channel") + " record" + learn_fault());
    } else if (u.op == kMessage) {
      mcap::Message msg;
      if (!parse_message(u.content, msg)) fail(u.at, "corrupt MCAP Message record");
      if (!channels_.count(msg.channel_id))
        fail(u.at, "MCAP Message on channel " + std::to_string(msg.channel_id) +
                       ", which no Channel record defines before it");
      if (wanted(msg.channel_id)) {
        m = Message{msg.data, msg.log_time, next_index_++, u.at};
        return true;
      }
    } else if (is_unknown_op(u.op)) {
      ++unknown_skipped_;
    }
  }
}

}  // namespace evlife::io::mcap
