// iniVation AEDAT 4.0 (DV): "#!AER-DAT4.0\r\n", i32 header size, FlatBuffer
// IOHeader (compression of the packets, offset of the file table, XML stream
// description), then packets: i32 stream id + i32 size + `size` bytes holding
// a size-prefixed FlatBuffer, LZ4- or Zstd-framed per the header. Only the
// polarity event stream ("EVTS") is decoded; frames, IMU and trigger packets
// are skipped and counted. Every packet is verified before it is read.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "chunked_file.h"
#include "evlife/io/event_reader.h"

struct LZ4F_dctx_s;
struct ZSTD_DCtx_s;

namespace evlife::io {

class Aedat4Reader final : public EventReader {
 public:
  /// Throws ReadError if the file cannot be opened, is not AEDAT 4.0, its
  /// header does not verify or it has no polarity event stream.
  explicit Aedat4Reader(const std::string& path);
  ~Aedat4Reader() override;
  Aedat4Reader(const Aedat4Reader&) = delete;
  Aedat4Reader& operator=(const Aedat4Reader&) = delete;

  std::size_t read(std::span<Event> out) override;
  std::optional<SensorSize> sensor_size() const override { return sensor_; }
  std::string_view format_name() const override { return "aedat4"; }
  const std::string& path() const override { return file_.path(); }
  /// Packets of other streams (frames, IMU, triggers) skipped: whole
  /// packets, each of many samples; only the triggers' are decoded.
  std::uint64_t skipped_record_count() const override { return skipped_packets_ + empty_event_packets_; }
  /// By their stream's type: imu-packet, trigger-packet, frame-packet,
  /// event-packet-of-another-stream (a second camera's), other-packet.
  std::vector<SkippedKindCount> skipped_record_kinds() const override;
  /// External input edges and pulses of the trigger streams' packets.
  std::uint64_t trigger_count() const override { return trigger_count_; }
  std::uint64_t bytes_consumed() const override {
    return static_cast<std::uint64_t>(file_.offset());
  }
  std::int32_t event_stream_id() const noexcept { return event_stream_id_; }

 private:
  enum class Compression { none, lz4, zstd };

  /// Loads the next event packet; false at the end or on a fault (error_ set).
  bool next_packet();
  bool decompress(std::int64_t packet_offset);
  /// The packet of `size` bytes after its header at `offset`, decompressed
  /// into packet_; false on a fault (error_ set).
  bool load_packet(std::int64_t offset, std::int32_t size);
  /// Adds a trigger packet's (in packet_) external edges to trigger_count_.
  bool count_triggers(std::int64_t offset);
  /// At data_end_: the file table there must decode and list packets that
  /// end there (a corrupt dataTablePosition ended the reading early, silently).
  bool data_table_ends_the_packets();
  void fail(std::int64_t byte_offset, const std::string& what);

  ChunkedFile file_;
  Compression compression_ = Compression::none;
  std::int32_t event_stream_id_ = -1;
  std::int64_t data_end_ = 0;  // file table offset, else the file size
  std::optional<SensorSize> sensor_;
  LZ4F_dctx_s* lz4_ = nullptr;
  ZSTD_DCtx_s* zstd_ = nullptr;
  std::vector<std::uint8_t> compressed_;  // one packet as stored; grows to the largest
  std::vector<std::uint8_t> packet_;      // one packet decompressed
  std::size_t compressed_bytes_ = 0;      // bytes in use of compressed_ / packet_
  std::size_t packet_bytes_ = 0;
  std::size_t compressed_used_ = 0;       // of compressed_bytes_, by the last decompress(): its frame's
  const std::uint8_t* events_ = nullptr;  // 16-byte event records inside packet_
  std::size_t events_size_ = 0;
  std::size_t events_pos_ = 0;
  std::int64_t packet_offset_ = 0;
  std::uint64_t skipped_packets_ = 0;
  std::uint64_t empty_event_packets_ = 0;  // event packets without elements (a damaged vector drops them)
  std::uint64_t trigger_count_ = 0;
  std::array<std::uint64_t, 5> skipped_by_kind_{};  // [kind] (aedat4_reader.cpp: kSkippedPacketKinds)
  std::vector<std::pair<std::int32_t, std::size_t>> other_streams_;  // the header's other streams: id, kind
  std::int64_t event_count_ = 0;
  std::optional<ReadError> error_;
  bool table_checked_ = false;
};

}  // namespace evlife::io
