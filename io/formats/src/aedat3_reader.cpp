// iniVation cAER AEDAT 3.1: `#!AER-DAT3.1` and `#` header lines up to
// `#!END-HEADER`, then packets: a 28-byte little-endian header (i16 type,
// i16 source, i32 eventSize, i32 eventTSOffset, i32 eventTSOverflow,
// i32 eventCapacity, i32 eventNumber, i32 eventValid) and eventNumber events
// of eventSize bytes. Polarity packets (type 1, 8-byte events: u32 data with
// bit 0 valid, bit 1 polarity, bits 2-16 y, bits 17-31 x; i32 timestamp µs)
// are decoded, t = eventTSOverflow << 31 | timestamp; y = 0 is the top row
// (libcaer's origin). Events without the valid bit, and every other packet,
// are skipped and counted per kind: the event type ids of the AEDAT 3.1
// specification (docs.inivation.com, file-formats/aedat-3.1; libcaer
// events/common.h): 0 special, 2 frame, 3 imu6, 4 imu9, 5 sample, 6 ear,
// 7 config, 8-11 point1d-point4d, 12 spike, 13 matrix4x4; any other id is
// counted as "unknown-type".
// Special packets (type 0, 8-byte events: u32 data with bit 0 valid, bits
// 1-7 the special type, bits 8-31 its data; i32 timestamp) are decoded: the
// external-input kinds of libcaer's events/special.h are the triggers,
// counted as "trigger" (trigger_count(), as AEDAT 2.0 external events and the
// ROS payloads' trigger events): 2/3/4 EXTERNAL_INPUT_RISING_EDGE /
// FALLING_EDGE / PULSE, 6/7/8 EXTERNAL_INPUT1_..., 9/10/11 EXTERNAL_INPUT2_...
// Every other valid special event (timestamp wrap and reset, DVS row only,
// the generator's own edges 12/13, APS frame and exposure markers, ...) is
// counted as "special", events without the valid bit as "special-invalid".
// One camera: the source of the first polarity packet. Polarity packets of
// another source (a second camera of a cAER setup) are skipped and counted
// as "polarity-other-source" (they were read as the first camera's).
#include <algorithm>
#include <array>
#include <cstring>
#include <optional>
#include <vector>

#include "input_file.h"
#include "reader_registry.h"
#include "skipped_kinds.h"

namespace evlife::io::detail {
namespace {

constexpr std::string_view kAedat3Magic = "#!AER-DAT3.1";
constexpr std::string_view kEndHeader = "#!END-HEADER";
constexpr std::size_t kPacketHeader = 28;
constexpr std::int16_t kSpecial = 0;
constexpr std::int16_t kPolarity = 1;
constexpr std::uint64_t kAedat3MaxPacketBytes = std::uint64_t{64} << 20;

// Skipped kinds: index = event type id for 0..13 (0: the special events that
// are not triggers); then evlife's own.
constexpr std::size_t kInvalidPolarity = 14;
constexpr std::size_t kUnknownType = 15;
constexpr std::size_t kTrigger = 16;
constexpr std::size_t kInvalidSpecial = 17;
constexpr std::size_t kOtherSourcePolarity = 18;
constexpr std::array<std::string_view, 19> kAedat3SkippedNames{
    "special", "polarity", "frame", "imu6", "imu9", "sample", "ear", "config", "point1d", "point2d",
    "point3d", "point4d", "spike", "matrix4x4", "polarity-invalid", "unknown-type", "trigger",
    "special-invalid", "polarity-other-source"};

/// libcaer's special event types of an external input (a trigger).
constexpr bool is_external_input(std::uint32_t type) {
  return (type >= 2 && type <= 4) || (type >= 6 && type <= 11);
}

class Aedat3Reader final : public EventReader {
 public:
  explicit Aedat3Reader(const std::string& path) : file_(path) { offset_ = header_end(); }

  std::size_t read(std::span<Event> out) override {
    std::size_t n = 0;
    while (n < out.size()) {
      if (next_ == events_.size()) {
        if (error_ || ended_) break;
        load_packet();
        continue;
      }
      const std::size_t k = std::min(out.size() - n, events_.size() - next_);
      std::copy_n(events_.begin() + static_cast<std::ptrdiff_t>(next_), k, out.begin() + static_cast<std::ptrdiff_t>(n));
      n += k;
      next_ += k;
      delivered_ += static_cast<std::int64_t>(k);
    }
    if (n == 0 && error_) throw *error_;
    return n;
  }

  std::optional<SensorSize> sensor_size() const override { return std::nullopt; }
  std::string_view format_name() const override { return "aedat3"; }
  const std::string& path() const override { return file_.path(); }
  std::uint64_t skipped_record_count() const override { return skipped_.total(); }
  std::uint64_t trigger_count() const override { return skipped_.count(kTrigger); }
  std::vector<SkippedKindCount> skipped_record_kinds() const override { return skipped_.seen(); }
  std::uint64_t bytes_consumed() const override { return offset_; }

 private:
  /// Offset of the first packet (after the `#!END-HEADER` line).
  std::uint64_t header_end() const {
    std::vector<char> head(std::min<std::uint64_t>(file_.size_bytes(), 1 << 20));
    file_.read_at(0, std::as_writable_bytes(std::span(head)));
    const std::string_view text(head.data(), head.size());
    if (!text.starts_with(kAedat3Magic)) throw ReadError(file_.path(), 0, -1, "not an AEDAT 3.1 file");
    const std::size_t end = text.find(kEndHeader);
    if (end == std::string_view::npos)
      throw ReadError(file_.path(), 0, -1, "AEDAT 3.1 header without '#!END-HEADER' in its first MiB");
    const std::size_t nl = text.find('\n', end);
    if (nl == std::string_view::npos) throw ReadError(file_.path(), static_cast<std::int64_t>(end), -1, "truncated AEDAT 3.1 header");
    return nl + 1;
  }

  void fault(std::uint64_t at, const std::string& what) {
    error_.emplace(file_.path(), static_cast<std::int64_t>(at), delivered_ + static_cast<std::int64_t>(events_.size()), what);
  }

  void load_packet() {
    events_.clear();
    next_ = 0;
    const std::uint64_t at = offset_;
    if (at == file_.size_bytes()) {
      ended_ = true;
      return;
    }
    std::array<std::byte, kPacketHeader> h{};
    if (file_.read_at(at, h) != h.size()) return fault(at, "truncated AEDAT 3.1 packet header");
    std::int16_t type = 0, source = 0;
    std::int32_t size = 0, ts_offset = 0, overflow = 0, capacity = 0, number = 0, valid = 0;
    std::memcpy(&type, h.data(), 2);
    std::memcpy(&source, h.data() + 2, 2);
    std::memcpy(&size, h.data() + 4, 4);
    std::memcpy(&ts_offset, h.data() + 8, 4);
    std::memcpy(&overflow, h.data() + 12, 4);
    std::memcpy(&capacity, h.data() + 16, 4);
    std::memcpy(&number, h.data() + 20, 4);
    std::memcpy(&valid, h.data() + 24, 4);
    if (size <= 0 || number < 0 ||
        static_cast<std::uint64_t>(size) * static_cast<std::uint64_t>(number) > kAedat3MaxPacketBytes)
      return fault(at, "corrupt AEDAT 3.1 packet header (event size " + std::to_string(size) + ", " +
                           std::to_string(number) + " events)");
    // What every packet's header holds (libcaer): the timestamp inside the
    // event and after its first byte (every event type's valid mark), at
    // most `capacity` events, at most `number` of them valid. A header read
    // from the wrong offset (bytes lost before it) rarely holds it, and was
    // skipped as a packet of some other type, exit 0.
    if (ts_offset < 1 || ts_offset > size - 4 || capacity < number || valid < 0 || valid > number)
      return fault(at, "corrupt AEDAT 3.1 packet header (type " + std::to_string(type) + ", event size " +
                           std::to_string(size) + ", timestamp offset " + std::to_string(ts_offset) + ", capacity " +
                           std::to_string(capacity) + ", " + std::to_string(number) + " events, " +
                           std::to_string(valid) + " valid; bytes lost or damaged before it?)");
    const std::uint64_t bytes = static_cast<std::uint64_t>(size) * static_cast<std::uint64_t>(number);
    const std::uint64_t body = at + kPacketHeader;
    const std::uint64_t available = std::min<std::uint64_t>(bytes, file_.size_bytes() - std::min(body, file_.size_bytes()));
    if (type == kSpecial) return load_special(at, size, available, bytes);
    if (type == kPolarity && !camera_source_) camera_source_ = source;
    if (type != kPolarity || source != *camera_source_) {
      const bool known = type >= 0 && static_cast<std::size_t>(type) < kInvalidPolarity;
      skipped_.add(type == kPolarity ? kOtherSourcePolarity : known ? static_cast<std::size_t>(type) : kUnknownType,
                   static_cast<std::uint64_t>(number));
      if (available < bytes) return fault(body + available, "truncated AEDAT 3.1 packet");
      offset_ = body + bytes;
      return;
    }
    if (size != 8) return fault(at, "AEDAT 3.1 polarity packet with " + std::to_string(size) + "-byte events (8 expected)");
    if (overflow < 0) return fault(at, "AEDAT 3.1 packet with a negative timestamp overflow");
    raw_.resize(available);
    file_.read_at(body, std::as_writable_bytes(std::span(raw_)));
    const std::size_t whole = available / 8;
    events_.reserve(whole);
    const std::int64_t high = static_cast<std::int64_t>(overflow) << 31;
    for (std::size_t i = 0; i < whole; ++i) {
      std::uint32_t data = 0;
      std::int32_t ts = 0;
      std::memcpy(&data, raw_.data() + 8 * i, 4);
      std::memcpy(&ts, raw_.data() + 8 * i + 4, 4);
      if ((data & 1u) == 0) {
        skipped_.add(kInvalidPolarity);
        continue;
      }
      if (ts < 0) return fault(body + 8 * i, "AEDAT 3.1 polarity event with a negative timestamp");
      events_.push_back(Event{high | ts, static_cast<std::uint16_t>((data >> 17) & 0x7FFFu),
                              static_cast<std::uint16_t>((data >> 2) & 0x7FFFu),
                              (data & 2u) != 0 ? std::int8_t{1} : std::int8_t{-1}});
    }
    if (available < bytes) return fault(body + whole * 8, "truncated AEDAT 3.1 polarity packet");
    offset_ = body + bytes;
  }

  /// A special packet: every event counted as trigger, special or invalid.
  void load_special(std::uint64_t at, std::int32_t size, std::uint64_t available, std::uint64_t bytes) {
    if (size != 8) return fault(at, "AEDAT 3.1 special packet with " + std::to_string(size) + "-byte events (8 expected)");
    const std::uint64_t body = at + kPacketHeader;
    raw_.resize(available);
    file_.read_at(body, std::as_writable_bytes(std::span(raw_)));
    const std::size_t whole = available / 8;
    for (std::size_t i = 0; i < whole; ++i) {
      std::uint32_t data = 0;
      std::memcpy(&data, raw_.data() + 8 * i, 4);
      if ((data & 1u) == 0) skipped_.add(kInvalidSpecial);
      else skipped_.add(is_external_input((data >> 1) & 0x7Fu) ? kTrigger : 0);
    }
    if (available < bytes) return fault(body + whole * 8, "truncated AEDAT 3.1 special packet");
    offset_ = body + bytes;
  }

  InputFile file_;
  std::uint64_t offset_ = 0;
  std::vector<std::uint8_t> raw_;
  std::vector<Event> events_;
  std::size_t next_ = 0;
  std::int64_t delivered_ = 0;
  SkippedKinds<kAedat3SkippedNames.size()> skipped_{kAedat3SkippedNames};
  bool ended_ = false;
  std::optional<ReadError> error_;
  std::optional<std::int16_t> camera_source_;  // of the first polarity packet
};

SniffResult sniff_aedat3(std::span<const std::byte> head, std::string_view /*path*/) {
  return head.size() >= kAedat3Magic.size() && std::memcmp(head.data(), kAedat3Magic.data(), kAedat3Magic.size()) == 0
             ? SniffResult::by_content
             : SniffResult::no;
}

std::unique_ptr<EventReader> open_aedat3(const std::string& path) { return std::make_unique<Aedat3Reader>(path); }

}  // namespace

const ReaderFormat aedat3_format{"aedat3",
                                 "iniVation cAER AEDAT 3.1 ('#!AER-DAT3.1'): polarity packets (of the first source); external-input "
                                 "special events counted as triggers; frames, IMU, other special events "
                                 "and other packets skipped and counted per kind",
                                 &sniff_aedat3, &open_aedat3};

}  // namespace evlife::io::detail
