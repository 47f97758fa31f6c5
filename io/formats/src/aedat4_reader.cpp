#include "aedat4_reader.h"

#include <lz4frame.h>
#include <zstd.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cstring>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "aedat4_generated.h"
#include "reader_registry.h"

namespace evlife::io {
namespace {

constexpr std::string_view kAedat4Magic = "#!AER-DAT4.0\r\n";
constexpr std::size_t kEventBytes = 16;       // i64 t, i16 x, i16 y, u8 polarity, 3 pad
constexpr std::size_t kAedat4MaxPacketBytes = std::size_t{256} << 20;  // sanity bound (corrupt sizes)
constexpr std::int32_t kMaxHeaderBytes = 16 << 20;

struct StreamInfo {
  std::int32_t id = -1;
  std::optional<SensorSize> sensor;
  std::vector<std::pair<std::int32_t, std::size_t>> others;  // every other stream: id, its kind's index
};

// What a skipped packet holds, by its stream's typeIdentifier: the kinds of
// skipped_record_kinds(), in that order (the last for any other type).
// (EVTS: a second polarity stream, another camera's: only the first is read.)
constexpr std::array<std::pair<std::string_view, std::string_view>, 5> kSkippedPacketKinds{{
    {"IMUS", "imu-packet"},
    {"TRIG", "trigger-packet"},
    {"FRME", "frame-packet"},
    {"EVTS", "event-packet-of-another-stream"},
    {"", "other-packet"}}};
constexpr std::size_t kTriggerKind = 1;  // decoded: its external edges are trigger_count()

// Whether a stream's node states typeIdentifier `type` (EVTS, IMUS, ...).
bool stream_type_is(std::string_view node, std::string_view type) {
  return node.find("key=\"typeIdentifier\" type=\"string\">" + std::string(type) + "<") != std::string_view::npos;
}

std::size_t packet_kind_of(std::string_view node) {
  for (std::size_t k = 0; k + 1 < kSkippedPacketKinds.size(); ++k)
    if (stream_type_is(node, kSkippedPacketKinds[k].first)) return k;
  return kSkippedPacketKinds.size() - 1;
}

// Integer value of `<attr key="KEY" type="int">N</attr>` in `xml`, if any.
std::optional<int> xml_int_attr(std::string_view xml, std::string_view key) {
  const std::string needle = "key=\"" + std::string(key) + "\"";
  const std::size_t at = xml.find(needle);
  if (at == std::string_view::npos) return std::nullopt;
  const std::size_t gt = xml.find('>', at);
  if (gt == std::string_view::npos) return std::nullopt;
  int value = 0;
  const auto [end, ec] = std::from_chars(xml.data() + gt + 1, xml.data() + xml.size(), value);
  if (ec != std::errc() || end == xml.data() + gt + 1) return std::nullopt;
  return value;
}

// The first stream of type EVTS in the header's XML, and the others' kinds:
// streams are the nodes named by a number under outInfo, e.g. <node name="0"
// path=".../outInfo/0/">.
StreamInfo find_event_stream(std::string_view xml) {
  StreamInfo info;
  std::vector<std::pair<std::int32_t, std::size_t>> streams;  // id, start of its node
  for (std::size_t at = xml.find("<node name=\""); at != std::string_view::npos;
       at = xml.find("<node name=\"", at + 1)) {
    const char* digits = xml.data() + at + 12;
    std::int32_t id = 0;
    const auto [end, ec] = std::from_chars(digits, xml.data() + xml.size(), id);
    if (ec == std::errc() && end != digits && *end == '"') streams.emplace_back(id, at);
  }
  for (std::size_t i = 0; i < streams.size(); ++i) {
    const std::size_t begin = streams[i].second;
    const std::size_t end = i + 1 < streams.size() ? streams[i + 1].second : xml.size();
    const std::string_view node = xml.substr(begin, end - begin);
    if (info.id >= 0 || !stream_type_is(node, "EVTS")) {
      info.others.emplace_back(streams[i].first, packet_kind_of(node));
      continue;
    }
    info.id = streams[i].first;
    const auto w = xml_int_attr(node, "sizeX");
    const auto h = xml_int_attr(node, "sizeY");
    if (w && h && *w > 0 && *h > 0) info.sensor = SensorSize{*w, *h};
  }
  return info;
}

}  // namespace

Aedat4Reader::Aedat4Reader(const std::string& path) : file_(path) {
  const std::size_t prefix = kAedat4Magic.size() + 4;
  if (file_.fill(prefix) < prefix ||
      std::memcmp(file_.data(), kAedat4Magic.data(), kAedat4Magic.size()) != 0) {
    throw ReadError(path, 0, -1, "not an AEDAT 4.0 file (no '#!AER-DAT4.0' line)");
  }
  file_.consume(kAedat4Magic.size());
  // The i32 header size is the size prefix of the IOHeader FlatBuffer (its
  // alignment counts from there), so the buffer verified starts with it.
  std::int32_t header_bytes;
  std::memcpy(&header_bytes, file_.data(), 4);
  const std::int64_t header_offset = file_.offset();
  if (header_bytes <= 0 || header_bytes > kMaxHeaderBytes ||
      header_offset + 4 + header_bytes > file_.size_bytes()) {
    throw ReadError(path, header_offset, -1,
                    "AEDAT 4.0 header size " + std::to_string(header_bytes) +
                        " is invalid or beyond the end of the file");
  }
  std::vector<std::uint8_t> header(4 + static_cast<std::size_t>(header_bytes));
  file_.read(header.data(), header.size());
  flatbuffers::Verifier verifier(header.data(), header.size());
  if (!verifier.VerifySizePrefixedBuffer<aedat4::IOHeader>("IOHE")) {
    throw ReadError(path, header_offset, -1, "AEDAT 4.0 header (FlatBuffer IOHeader) is corrupt");
  }
  const auto* io_header = flatbuffers::GetSizePrefixedRoot<aedat4::IOHeader>(header.data());
  switch (io_header->compression()) {
    case aedat4::CompressionType::NONE: compression_ = Compression::none; break;
    case aedat4::CompressionType::LZ4:
    case aedat4::CompressionType::LZ4_HIGH: compression_ = Compression::lz4; break;
    case aedat4::CompressionType::ZSTD:
    case aedat4::CompressionType::ZSTD_HIGH: compression_ = Compression::zstd; break;
    default:
      throw ReadError(path, header_offset, -1,
                      "unknown AEDAT 4.0 compression type " +
                          std::to_string(static_cast<int>(io_header->compression())));
  }
  const std::string_view xml =
      io_header->info_node() != nullptr ? io_header->info_node()->string_view() : std::string_view{};
  const StreamInfo stream = find_event_stream(xml);
  if (stream.id < 0) {
    throw ReadError(path, header_offset, -1,
                    "AEDAT 4.0 file has no polarity event stream (typeIdentifier EVTS)");
  }
  event_stream_id_ = stream.id;
  other_streams_ = stream.others;
  sensor_ = stream.sensor;
  const std::int64_t table = io_header->data_table_position();
  data_end_ = table > file_.offset() ? table : file_.size_bytes();

  if (compression_ == Compression::lz4 &&
      LZ4F_isError(LZ4F_createDecompressionContext(&lz4_, LZ4F_VERSION))) {
    throw ReadError(path, -1, -1, "cannot create an LZ4 decompression context");
  }
  if (compression_ == Compression::zstd && (zstd_ = ZSTD_createDCtx()) == nullptr) {
    throw ReadError(path, -1, -1, "cannot create a Zstd decompression context");
  }
}

Aedat4Reader::~Aedat4Reader() {
  if (lz4_ != nullptr) LZ4F_freeDecompressionContext(lz4_);
  if (zstd_ != nullptr) ZSTD_freeDCtx(zstd_);
}

void Aedat4Reader::fail(std::int64_t byte_offset, const std::string& what) {
  error_.emplace(path(), byte_offset, event_count_, what);
}

bool Aedat4Reader::decompress(std::int64_t packet_offset) {
  // Buffers only grow (no per-packet clearing); *_bytes_ say what is in use.
  if (packet_.size() < 4 * compressed_bytes_) packet_.resize(4 * compressed_bytes_);
  std::size_t in_pos = 0;
  std::size_t out_pos = 0;
  while (true) {
    if (out_pos == packet_.size()) {
      if (packet_.size() >= kAedat4MaxPacketBytes) {
        fail(packet_offset, "AEDAT 4.0 packet decompresses to more than 256 MiB (corrupt?)");
        return false;
      }
      packet_.resize(std::min(2 * packet_.size(), kAedat4MaxPacketBytes));
    }
    std::size_t in_bytes = compressed_bytes_ - in_pos;
    std::size_t out_bytes = packet_.size() - out_pos;
    std::size_t hint;
    if (compression_ == Compression::lz4) {
      hint = LZ4F_decompress(lz4_, packet_.data() + out_pos, &out_bytes,
                             compressed_.data() + in_pos, &in_bytes, nullptr);
      if (LZ4F_isError(hint)) {
        LZ4F_resetDecompressionContext(lz4_);
        fail(packet_offset, std::string("AEDAT 4.0 packet: corrupt LZ4 data (") +
                                LZ4F_getErrorName(hint) + ")");
        return false;
      }
    } else {
      ZSTD_inBuffer in{compressed_.data() + in_pos, in_bytes, 0};
      ZSTD_outBuffer out{packet_.data() + out_pos, out_bytes, 0};
      hint = ZSTD_decompressStream(zstd_, &out, &in);
      if (ZSTD_isError(hint)) {
        ZSTD_DCtx_reset(zstd_, ZSTD_reset_session_only);
        fail(packet_offset, std::string("AEDAT 4.0 packet: corrupt Zstd data (") +
                                ZSTD_getErrorName(hint) + ")");
        return false;
      }
      in_bytes = in.pos;
      out_bytes = out.pos;
    }
    in_pos += in_bytes;
    out_pos += out_bytes;
    if (hint == 0) break;  // frame complete
    if (in_pos == compressed_bytes_ && out_pos < packet_.size()) {
      fail(packet_offset, "AEDAT 4.0 packet: compressed frame is incomplete");
      return false;
    }
  }
  packet_bytes_ = out_pos;
  compressed_used_ = in_pos;
  return true;
}

namespace {

// The packets a file table lists end where the table starts. Writers differ
// in what an entry's byte_offset names: dv-processing the packet's data,
// after its 8-byte header (sample.aedat4), jAER the header itself
// (Aedat4FileOutputStream); either layout is a table of this file.
bool table_ends_at(const std::uint8_t* bytes, std::size_t size, std::int64_t at) {
  flatbuffers::Verifier verifier(bytes, size);
  if (!verifier.VerifySizePrefixedBuffer<aedat4::FileDataTable>(nullptr)) return false;
  const auto* table = flatbuffers::GetSizePrefixedRoot<aedat4::FileDataTable>(bytes);
  if (table->definitions() == nullptr || table->definitions()->size() == 0) return true;  // lists nothing
  std::int64_t data_end = -1;
  for (const aedat4::FileDataDefinition* d : *table->definitions()) {
    if (d != nullptr && d->packet_info() != nullptr)
      data_end = std::max(data_end, d->byte_offset() + d->packet_info()->size());
  }
  return data_end == at || data_end + 8 == at;
}

}  // namespace

bool Aedat4Reader::data_table_ends_the_packets() {
  if (table_checked_ || data_end_ >= file_.size_bytes()) return true;  // checked, or no table
  table_checked_ = true;
  const std::int64_t at = data_end_;
  const auto bytes = static_cast<std::uint64_t>(file_.size_bytes() - at);
  const std::string whence = "the header's dataTablePosition, byte " + std::to_string(at) + ",";
  if (bytes > kAedat4MaxPacketBytes) {
    fail(at, whence + " leaves more than 256 MiB for the file table: a corrupt header?");
    return false;
  }
  // The table is compressed as the packets (dv-processing) or not (jAER).
  std::vector<std::uint8_t>& raw = compression_ == Compression::none ? packet_ : compressed_;
  if (raw.size() < bytes) raw.resize(bytes);
  (compression_ == Compression::none ? packet_bytes_ : compressed_bytes_) = bytes;
  if (file_.read(raw.data(), bytes) != bytes) {
    fail(at, whence + " but the table cannot be read");
    return false;
  }
  // Where the table ends in the file: the bytes after it would be lost
  // unseen (a second recording appended to this one, or garbage).
  std::int64_t table_end = 0;
  if (table_ends_at(raw.data(), bytes, at)) {
    table_end = at + 4 + static_cast<std::int64_t>(flatbuffers::GetPrefixedSize(raw.data()));
  } else if (compression_ != Compression::none) {
    if (decompress(at) && table_ends_at(packet_.data(), packet_bytes_, at)) table_end = at + static_cast<std::int64_t>(compressed_used_);
    error_.reset();  // decompress()'s own message would name a packet
  }
  if (table_end == 0) {
    fail(at, whence + " holds no file table listing the packets before it: a corrupt header? The packets before byte " +
                 std::to_string(at) + " were read");
    return false;
  }
  if (table_end < file_.size_bytes()) {
    fail(table_end,
         std::to_string(file_.size_bytes() - table_end) + " bytes after the file table (bytes " + std::to_string(at) +
             " to " + std::to_string(table_end) +
             "), which no packet holds: another recording appended to this one, or garbage? The packets before "
             "byte " + std::to_string(at) + " were read");
    return false;
  }
  return true;
}

bool Aedat4Reader::load_packet(std::int64_t offset, std::int32_t size) {
  std::vector<std::uint8_t>& raw = compression_ == Compression::none ? packet_ : compressed_;
  if (raw.size() < static_cast<std::size_t>(size)) raw.resize(static_cast<std::size_t>(size));
  (compression_ == Compression::none ? packet_bytes_ : compressed_bytes_) = static_cast<std::size_t>(size);
  if (file_.read(raw.data(), static_cast<std::size_t>(size)) != static_cast<std::size_t>(size)) {
    fail(offset, "truncated AEDAT 4.0 packet");
    return false;
  }
  if (compression_ == Compression::none) return true;
  if (!decompress(offset)) return false;
  // One frame per packet, as DV writes it: what follows it was never read.
  if (compressed_used_ < compressed_bytes_) {
    fail(offset, "AEDAT 4.0 packet: " + std::to_string(compressed_bytes_ - compressed_used_) +
                     " bytes after its compressed frame (a second frame, or garbage), which were not read");
    return false;
  }
  return true;
}

bool Aedat4Reader::count_triggers(std::int64_t offset) {
  flatbuffers::Verifier verifier(packet_.data(), packet_bytes_);
  if (!verifier.VerifySizePrefixedBuffer<aedat4::TriggerPacket>(nullptr)) {
    fail(offset, "AEDAT 4.0 trigger packet does not verify (corrupt FlatBuffer)");
    return false;
  }
  const auto* packet = flatbuffers::GetSizePrefixedRoot<aedat4::TriggerPacket>(packet_.data());
  if (packet->elements() == nullptr) return true;
  for (const aedat4::Trigger* trigger : *packet->elements()) {
    // The external input's edges and pulses: what the other formats' `triggers` count (AEDAT 3's
    // special events too: the generator's own edges are not an input).
    const auto type = trigger->type();
    trigger_count_ += type >= aedat4::TriggerType::EXTERNAL_SIGNAL_RISING_EDGE &&
                      type <= aedat4::TriggerType::EXTERNAL_SIGNAL_PULSE;
  }
  return true;
}

bool Aedat4Reader::next_packet() {
  while (true) {
    if (file_.offset() >= data_end_) {
      (void)data_table_ends_the_packets();  // a fault: error_, raised after the events before it
      return false;
    }
    const std::int64_t offset = file_.offset();
    if (file_.fill(8) < 8) {
      fail(offset, "truncated AEDAT 4.0 packet header");
      return false;
    }
    std::int32_t stream_id;
    std::int32_t size;
    std::memcpy(&stream_id, file_.data(), 4);
    std::memcpy(&size, file_.data() + 4, 4);
    file_.consume(8);
    if (size <= 0 || static_cast<std::size_t>(size) > kAedat4MaxPacketBytes ||
        offset + 8 + size > std::min(data_end_, file_.size_bytes())) {
      fail(offset, "AEDAT 4.0 packet of " + std::to_string(size) + " bytes (stream " +
                       std::to_string(stream_id) +
                       ") is invalid or runs past the end of the data (truncated file?)");
      return false;
    }
    if (stream_id != event_stream_id_) {  // frames, IMU, triggers
      ++skipped_packets_;
      std::size_t kind = kSkippedPacketKinds.size() - 1;  // a stream the header does not list: other
      for (const auto& [id, k] : other_streams_)
        if (id == stream_id) kind = k;
      ++skipped_by_kind_[kind];
      if (kind == kTriggerKind) {
        if (!load_packet(offset, size) || !count_triggers(offset)) return false;
      } else if (file_.available() >= static_cast<std::size_t>(size)) {
        file_.consume(static_cast<std::size_t>(size));
      } else {
        file_.seek(offset + 8 + size);
      }
      continue;
    }
    packet_offset_ = offset;
    if (!load_packet(offset, size)) return false;

    flatbuffers::Verifier verifier(packet_.data(), packet_bytes_);
    if (!aedat4::VerifySizePrefixedEventPacketBuffer(verifier)) {
      fail(offset, "AEDAT 4.0 event packet does not verify (corrupt FlatBuffer)");
      return false;
    }
    const auto* packet = flatbuffers::GetSizePrefixedRoot<aedat4::EventPacket>(packet_.data());
    events_pos_ = 0;
    events_size_ = 0;
    if (packet->elements() != nullptr) {
      events_ = reinterpret_cast<const std::uint8_t*>(packet->elements()->Data());
      events_size_ = packet->elements()->size();
      // A FlatBufferBuilder creates the elements vector first, so it ends
      // the buffer: room for a whole event after it means a damaged count
      // (a shortened one would drop the packet's tail unsaid).
      const auto after_events = static_cast<std::size_t>(packet_.data() + packet_bytes_ - events_) -
                                events_size_ * kEventBytes;
      if (after_events >= kEventBytes) {
        fail(offset, "AEDAT 4.0 event packet counts " + std::to_string(events_size_) + " events, yet " +
                         std::to_string(after_events) +
                         " bytes follow them inside the packet, which its events end when written "
                         "(a damaged count; the packet is not read)");
        return false;
      }
    }
    if (events_size_ > 0) return true;
    ++empty_event_packets_;  // (a damaged elements field reads as none: said, not silent)
  }
}

std::size_t Aedat4Reader::read(std::span<Event> out) {
  if (error_) throw *error_;
  // Unsigned bounds: a negative int16 coordinate becomes huge and fails too.
  const auto width = static_cast<std::uint32_t>(sensor_ ? sensor_->width : 32768);
  const auto height = static_cast<std::uint32_t>(sensor_ ? sensor_->height : 32768);
  std::size_t n = 0;
  while (n < out.size()) {
    if (events_pos_ == events_size_) {
      if (!next_packet()) break;
    }
    const std::size_t count = std::min(events_size_ - events_pos_, out.size() - n);
    const std::uint8_t* records = events_ + events_pos_ * kEventBytes;
    // Convert first, branch-free; find a bad coordinate only if there is one.
    bool bad = false;
    for (std::size_t i = 0; i < count; ++i) {
      const std::uint8_t* record = records + i * kEventBytes;
      std::int16_t x;
      std::int16_t y;
      Event& e = out[n + i] = Event{};  // a whole event (EventReader::read)
      std::memcpy(&e.t_us, record, 8);
      std::memcpy(&x, record + 8, 2);
      std::memcpy(&y, record + 10, 2);
      bad |= (static_cast<std::uint32_t>(static_cast<std::int32_t>(x)) >= width) |
             (static_cast<std::uint32_t>(static_cast<std::int32_t>(y)) >= height);
      e.x = static_cast<std::uint16_t>(x);
      e.y = static_cast<std::uint16_t>(y);
      e.p = record[12] != 0 ? std::int8_t{1} : std::int8_t{-1};
    }
    if (bad) {
      std::size_t i = 0;
      std::int16_t x = 0;
      std::int16_t y = 0;
      for (; i < count; ++i) {
        std::memcpy(&x, records + i * kEventBytes + 8, 2);
        std::memcpy(&y, records + i * kEventBytes + 10, 2);
        if (x < 0 || y < 0 || static_cast<std::uint32_t>(x) >= width ||
            static_cast<std::uint32_t>(y) >= height) {
          break;
        }
      }
      n += i;
      event_count_ += static_cast<std::int64_t>(i);
      events_pos_ += i;
      fail(packet_offset_, "AEDAT 4.0 event " + std::to_string(events_pos_) + " of its packet at x=" +
                               std::to_string(x) + " y=" + std::to_string(y) + " outside the sensor");
      events_size_ = events_pos_;
      if (n == 0) throw *error_;
      return n;
    }
    n += count;
    event_count_ += static_cast<std::int64_t>(count);
    events_pos_ += count;
  }
  if (error_ && n == 0) throw *error_;
  return n;
}

namespace detail {
namespace {

SniffResult sniff_aedat4(std::span<const std::byte> head, std::string_view /*path*/) {
  return head.size() >= kAedat4Magic.size() &&
                 std::memcmp(head.data(), kAedat4Magic.data(), kAedat4Magic.size()) == 0
             ? SniffResult::by_content
             : SniffResult::no;
}

std::unique_ptr<EventReader> open_aedat4(const std::string& path) {
  return std::make_unique<Aedat4Reader>(path);
}

}  // namespace

const ReaderFormat aedat4_format{"aedat4", "iniVation AEDAT 4.0 (DV; '#!AER-DAT4.0' header)",
                                 &sniff_aedat4, &open_aedat4};

}  // namespace detail
std::vector<SkippedKindCount> Aedat4Reader::skipped_record_kinds() const {
  std::vector<SkippedKindCount> kinds;
  for (std::size_t k = 0; k < kSkippedPacketKinds.size(); ++k)
    if (skipped_by_kind_[k] > 0) kinds.push_back({kSkippedPacketKinds[k].second, skipped_by_kind_[k]});
  if (empty_event_packets_ > 0) kinds.push_back({"event-packet-without-events", empty_event_packets_});
  return kinds;
}

}  // namespace evlife::io
