#include "mcap_records.h"

#include <lz4frame.h>
#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <cstring>
#include <limits>

namespace evlife::io::mcap {
namespace {

// Refuse chunks that would need absurd memory (the reader holds one chunk).
constexpr std::uint64_t kMcapMaxChunkBytes = std::uint64_t{1} << 28;  // 256 MiB
constexpr std::uint64_t kMaxLz4Ratio = 256;  // LZ4 cannot expand more than ~255:1

/// Sequential little-endian field reader over a record's content.
class RecordFields {
 public:
  explicit RecordFields(std::span<const std::uint8_t> b) : b_(b) {}
  template <typename T>
  bool get(T& v) {
    if (b_.size() - pos_ < sizeof(T)) return false;
    std::memcpy(&v, b_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return true;
  }
  bool bytes(std::uint64_t n, std::span<const std::uint8_t>& out) {
    if (n > b_.size() - pos_) return false;
    out = b_.subspan(pos_, static_cast<std::size_t>(n));
    pos_ += static_cast<std::size_t>(n);
    return true;
  }
  bool string(std::string& s) {
    std::uint32_t n = 0;
    std::span<const std::uint8_t> b;
    if (!get(n) || !bytes(n, b)) return false;
    s.assign(reinterpret_cast<const char*>(b.data()), b.size());
    return true;
  }
  /// A u32-length-prefixed map or array, returned whole.
  bool prefixed(std::span<const std::uint8_t>& out) {
    std::uint32_t n = 0;
    return get(n) && bytes(n, out);
  }
  std::span<const std::uint8_t> rest() const { return b_.subspan(pos_); }

 private:
  std::span<const std::uint8_t> b_;
  std::size_t pos_ = 0;
};

}  // namespace

bool parse_footer(std::span<const std::uint8_t> content, Footer& f) {
  RecordFields r(content);
  return r.get(f.summary_start) && r.get(f.summary_offset_start) && r.get(f.summary_crc);
}

bool parse_schema(std::span<const std::uint8_t> content, Schema& s) {
  RecordFields r(content);
  return r.get(s.id) && r.string(s.name) && r.string(s.encoding);  // data not needed
}

bool parse_channel(std::span<const std::uint8_t> content, Channel& c) {
  RecordFields r(content);
  std::span<const std::uint8_t> metadata;
  return r.get(c.id) && r.get(c.schema_id) && r.string(c.topic) && r.string(c.message_encoding) &&
         r.prefixed(metadata);
}

bool parse_message(std::span<const std::uint8_t> content, Message& m) {
  RecordFields r(content);
  if (!r.get(m.channel_id) || !r.get(m.sequence) || !r.get(m.log_time) || !r.get(m.publish_time))
    return false;
  m.data = r.rest();
  return true;
}

bool parse_chunk(std::span<const std::uint8_t> content, Chunk& c) {
  RecordFields r(content);
  std::uint64_t records_size = 0;
  return r.get(c.message_start_time) && r.get(c.message_end_time) && r.get(c.uncompressed_size) &&
         r.get(c.uncompressed_crc) && r.string(c.compression) && r.get(records_size) &&
         r.bytes(records_size, c.records);
}

bool parse_statistics(std::span<const std::uint8_t> content, std::map<std::uint16_t, std::uint64_t>& counts) {
  RecordFields r(content);
  std::uint64_t message_count = 0, start = 0, end = 0;
  std::uint16_t schemas = 0;
  std::uint32_t channels = 0, attachments = 0, metadata = 0, chunks = 0;
  std::span<const std::uint8_t> map;
  if (!r.get(message_count) || !r.get(schemas) || !r.get(channels) || !r.get(attachments) ||
      !r.get(metadata) || !r.get(chunks) || !r.get(start) || !r.get(end) || !r.prefixed(map))
    return false;
  counts.clear();
  RecordFields entries(map);
  while (!entries.rest().empty()) {
    std::uint16_t id = 0;
    std::uint64_t n = 0;
    if (!entries.get(id) || !entries.get(n)) return false;
    counts[id] = n;
  }
  return true;
}

std::optional<Record> record_at(std::span<const std::uint8_t> bytes, std::size_t pos) {
  if (pos > bytes.size() || bytes.size() - pos < kRecordPrefix) return std::nullopt;
  std::uint64_t length = 0;
  std::memcpy(&length, bytes.data() + pos + 1, 8);
  if (length > bytes.size() - pos - kRecordPrefix) return std::nullopt;
  return Record{bytes[pos], bytes.subspan(pos + kRecordPrefix, static_cast<std::size_t>(length))};
}

std::optional<std::string> decompress_chunk(const Chunk& c, std::vector<std::uint8_t>& out) {
  const std::string size = std::to_string(c.uncompressed_size);
  if (c.compression != "" && c.compression != "zstd" && c.compression != "lz4")
    return "chunk compressed with '" + c.compression + "' (readable: none, zstd, lz4)";
  if (c.uncompressed_size > kMcapMaxChunkBytes)
    return "chunk of " + size + " bytes uncompressed, over this reader's limit of " +
           std::to_string(kMcapMaxChunkBytes) + " bytes";
  const std::size_t n = static_cast<std::size_t>(c.uncompressed_size);
  if (c.compression.empty()) {
    if (c.records.size() != n)
      return "uncompressed chunk holds " + std::to_string(c.records.size()) + " bytes, its header says " + size;
    out.assign(c.records.begin(), c.records.end());
  } else if (c.records.empty()) {  // no frame at all: nothing inside
    if (n != 0) return "corrupt " + c.compression + " chunk (no data for its " + size + " bytes)";
    out.clear();
  } else if (c.compression == "zstd") {
    // A zstd stream may hold several frames (and skippable frames): their
    // declared sizes must add up to the chunk's, when every frame states one.
    std::uint64_t declared = 0;
    bool all_declared = true;
    for (std::size_t at = 0; at < c.records.size();) {
      const std::size_t frame = ZSTD_findFrameCompressedSize(c.records.data() + at, c.records.size() - at);
      const unsigned long long content = ZSTD_getFrameContentSize(c.records.data() + at, c.records.size() - at);
      if (ZSTD_isError(frame) || content == ZSTD_CONTENTSIZE_ERROR)
        return "corrupt zstd chunk (no valid zstd frame at byte " + std::to_string(at) + " of its data)";
      if (content == ZSTD_CONTENTSIZE_UNKNOWN) all_declared = false;
      else declared += std::min<unsigned long long>(content, kMcapMaxChunkBytes + 1);  // no overflow
      at += frame;
    }
    if (all_declared && declared != c.uncompressed_size)
      return "corrupt zstd chunk (frames of " + std::to_string(declared) + " bytes, header says " + size + ")";
    out.resize(n);
    const std::size_t r = ZSTD_decompress(out.data(), n, c.records.data(), c.records.size());
    if (ZSTD_isError(r) || r != n)
      return "corrupt zstd chunk (does not decompress to its " + size + " bytes" +
             (ZSTD_isError(r) ? std::string(": ") + ZSTD_getErrorName(r) : std::string()) + ")";
  } else {
    if (c.uncompressed_size > c.records.size() * kMaxLz4Ratio + 64)
      return "corrupt lz4 chunk (" + std::to_string(c.records.size()) + " bytes cannot hold " + size + ")";
    out.resize(n);
    LZ4F_dctx* ctx = nullptr;
    if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION))) return "lz4: out of memory";
    // An LZ4 frame stream may hold several frames (and skippable frames):
    // after a frame ends (LZ4F_decompress returns 0) the context starts the next.
    std::size_t in_at = 0, out_at = 0, r = 0;
    while (in_at < c.records.size()) {
      std::size_t out_len = n - out_at;
      std::size_t in_len = c.records.size() - in_at;
      r = LZ4F_decompress(ctx, out.data() + out_at, &out_len, c.records.data() + in_at, &in_len, nullptr);
      if (LZ4F_isError(r) || (in_len == 0 && out_len == 0)) break;  // an error, or the output is full
      in_at += in_len;
      out_at += out_len;
    }
    LZ4F_freeDecompressionContext(ctx);
    if (LZ4F_isError(r) || r != 0 || in_at != c.records.size() || out_at != n)
      return "corrupt lz4 chunk (does not decompress to its " + size + " bytes)";
  }
  if (c.uncompressed_crc != 0) {
    const std::uint32_t crc = crc32_update(0, out);
    if (crc != c.uncompressed_crc)
      return "chunk CRC mismatch (records CRC-32 " + std::to_string(crc) + ", header says " +
             std::to_string(c.uncompressed_crc) + ")";
  }
  return std::nullopt;
}

std::uint32_t crc32_update(std::uint32_t crc, std::span<const std::uint8_t> bytes) {
  uLong c = crc;
  for (std::size_t at = 0; at < bytes.size();) {  // crc32 takes uInt lengths
    const std::size_t k = std::min<std::size_t>(bytes.size() - at, std::numeric_limits<uInt>::max());
    c = crc32(c, bytes.data() + at, static_cast<uInt>(k));
    at += k;
  }
  return static_cast<std::uint32_t>(c);
}

}  // namespace evlife::io::mcap
