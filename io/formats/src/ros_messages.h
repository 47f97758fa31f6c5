// Event messages of ROS 2 bags (CDR, little-endian), decoded to events with
// nanosecond times. Shared by the bag containers (rosbag2_reader.cpp).
//
// Message types (ROS 2 names; the ROS 1 name without "/msg/" is accepted too):
//  - event_camera_msgs/msg/EventPacket and its older name
//    event_array_msgs/msg/EventArray: header, u32 height, u32 width, u64 seq,
//    u64 time_base, string encoding, bool is_bigendian, u8[] events, the
//    payload in one of the encodings
//      evt3    Prophesee EVT 3.0 words (Evt3Decoder; one decoder keeps its
//              state across the messages of a topic; time_base unused)
//      libcaer u32 data (bit 1 polarity, bits 2-16 y, bits 17-31 x) + i32 µs
//              per event: t = time_base + ts × 1000, and + 2^31 µs each time
//              ts decreases inside a message (the 32-bit sensor clock wraps)
//      mono    u64 per event (bit 63 polarity, 48-62 y, 32-47 x, 0-31 dt ns):
//              t = time_base + dt
//  - dvs_msgs/msg/EventArray and prophesee_event_msgs/msg/EventArray (same
//    layout): header, u32 height, u32 width, Event[] with u16 x, u16 y,
//    builtin_interfaces/Time ts (i32 sec, u32 nanosec), bool polarity.
// TIME RULE (every ROS source): event times are the times the events carry
// (payload / per-event stamps, as above); message header stamps and bag
// receive times are not used. Readers floor them to µs.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "evlife/algo/event.h"
#include "evt3_decoder.h"

namespace evlife::io::ros {

/// One decoded event; t in ns (the unit of ROS times).
struct RosEvent {
  std::int64_t t_ns;
  std::uint16_t x;
  std::uint16_t y;
  std::int8_t p;  ///< +1 ON, -1 OFF
};

/// Copies events[next...] into `out` as evlife events (time floored to us;
/// t_ns >= 0 for every decoder), advancing `next`; returns how many. The one
/// conversion both bag readers use.
std::size_t take_events(const std::vector<RosEvent>& events, std::size_t& next, std::span<Event> out) noexcept;

enum class MessageKind { event_packet, event_array, not_events };

/// ROS 2 CDR (4-byte encapsulation header, primitives aligned to their size)
/// or ROS 1 (no header, packed; std_msgs/Header starts with a u32 seq).
enum class Serialization { cdr, ros1 };

/// The kind of a message type name (ROS 1 "pkg/Type" or ROS 2 "pkg/msg/Type").
MessageKind message_kind(std::string_view type);

/// Type names readable as events, for error messages.
std::string_view known_message_types();
/// The same, as a literal for the formats' descriptions (reader_registry.h).
#define EVLIFE_ROS_EVENT_MESSAGE_TYPES                                                     \
  "event_camera_msgs/EventPacket (evt3, libcaer, libcaer_cmp, mono), event_array_msgs/EventArray, " \
  "dvs_msgs/EventArray, prophesee_event_msgs/EventArray, dv_ros_msgs/EventArray"

/// Where and why a message could not be decoded.
struct MessageFault {
  std::size_t byte_in_message = 0;
  std::string what;
};

/// What libcaer_cmp's words leave set for the next (decode_libcaer_cmp).
struct LibcaerCmpState {
  std::int32_t x = -1;       ///< -1: no ADDR_X yet
  std::int32_t base_y = -1;  ///< -1: no VECT_BASE_Y yet
  std::int8_t polarity = 1;
};

class MessageDecoder {
 public:
  explicit MessageDecoder(MessageKind kind, Serialization serialization = Serialization::cdr)
      : kind_(kind), serialization_(serialization) {}

  /// Decodes one serialized message (CDR: with its 4-byte encapsulation
  /// header) into `out` (cleared first). On bad data returns the fault; the
  /// events decoded before it stay in `out`.
  std::optional<MessageFault> decode(std::span<const std::uint8_t> message,
                                     std::vector<RosEvent>& out);

  /// width × height of the last decoded message (0 × 0 when it said none).
  std::uint32_t width() const noexcept { return width_; }
  std::uint32_t height() const noexcept { return height_; }
  /// Encoding of the last EventPacket ("" for event arrays).
  const std::string& encoding() const noexcept { return encoding_; }
  /// EVT 3.0 external trigger words seen (not mixed into the events).
  std::uint64_t trigger_count() const noexcept { return evt3_.trigger_count(); }
  /// Payload words that are neither events nor triggers (EVT 3.0 OTHERS...).
  std::uint64_t other_count() const noexcept { return evt3_.other_count(); }
  /// EVT 3.0 events before the stream's first TIME_HIGH: no time, skipped.
  std::uint64_t before_time_base_count() const noexcept { return evt3_.before_time_base_count(); }
  std::uint64_t before_address_count() const noexcept { return evt3_.before_address_count(); }
  /// libcaer events without their valid mark: skipped.
  std::uint64_t libcaer_invalid_count() const noexcept { return libcaer_invalid_; }
  void set_trigger_sink(Evt3TriggerSink* sink) noexcept { evt3_.set_trigger_sink(sink); }

 private:
  std::optional<MessageFault> decode_packet(std::span<const std::uint8_t> m, std::size_t base,
                                            std::vector<RosEvent>& out);
  std::optional<MessageFault> decode_array(std::span<const std::uint8_t> m, std::size_t base,
                                           std::vector<RosEvent>& out);

  MessageKind kind_;
  Serialization serialization_;
  std::uint32_t width_ = 0;
  std::uint32_t height_ = 0;
  std::string encoding_;
  Evt3Decoder evt3_;
  std::vector<Event> evt3_scratch_;
  LibcaerCmpState libcaer_cmp_;
  std::uint64_t libcaer_invalid_ = 0;
};

// Payload decoders of EventPacket (also used alone by the fuzz targets and
// the benchmarks). Each appends to `out` and returns the fault, if any, with
// the byte offset inside `payload`; width/height 0 = no bounds check.
/// libcaer: 8-byte polarity events (valid mark bit 0, polarity bit 1, y bits
/// 2-16, x bits 17-31; a 31-bit µs timestamp); events without the valid mark
/// are skipped and added to `invalid_count`.
std::optional<MessageFault> decode_libcaer(std::span<const std::uint8_t> payload, std::uint64_t time_base,
                                           std::uint32_t width, std::uint32_t height, std::vector<RosEvent>& out,
                                           std::uint64_t& invalid_count);
std::optional<MessageFault> decode_mono(std::span<const std::uint8_t> payload,
                                        std::uint64_t time_base, std::uint32_t width,
                                        std::uint32_t height, std::vector<RosEvent>& out);
/// libcaer_cmp (the ROS 2 libcaer driver's default): 16-bit little-endian
/// words, the code in bits 12-15: 0 TIME_HIGH (bits 0-11 = time bits 12-23),
/// 1 TIME_LOW (time bits 0-11; the time is µs after time_base (ns), both
/// zero at each message's start), 2 ADDR_X (x, bits 0-10), 3 ADDR_Y (an
/// event at (x, y bits 0-10), polarity bit 11, 1 = ON), 4 VECT_BASE_Y (base y,
/// polarity of the vectors after it), 5 VECT_8 (events at (x, base y + i) for each bit i of 0-7 set;
/// base y += 8). x, base y and polarity carry across messages (`state`), as
/// event_camera_codecs' decoder keeps them; other codes are a fault.
std::optional<MessageFault> decode_libcaer_cmp(std::span<const std::uint8_t> payload, std::uint64_t time_base,
                                               std::uint32_t width, std::uint32_t height, LibcaerCmpState& state,
                                               std::vector<RosEvent>& out);
/// `decoder` keeps its state between calls; `scratch` is reused memory.
std::optional<MessageFault> decode_evt3(std::span<const std::uint8_t> payload, Evt3Decoder& decoder,
                                        std::vector<Event>& scratch, std::vector<RosEvent>& out);

}  // namespace evlife::io::ros
