#include "ros_messages.h"

#include "wrapping_counter.h"

#include <algorithm>
#include <cstring>
#include <limits>

namespace evlife::io::ros {
namespace {

constexpr std::size_t kEncapsulationBytes = 4;
constexpr std::uint64_t kMaxTimeNs = static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());

/// Reads little-endian CDR: primitives aligned to their size, counted from
/// the byte after the encapsulation header (`base`).
class CdrCursor {
 public:
  CdrCursor(std::span<const std::uint8_t> m, std::size_t base, bool aligned = true)
      : m_(m), base_(base), pos_(base), aligned_(aligned) {}
  std::size_t pos() const noexcept { return pos_; }
  std::size_t remaining() const noexcept { return m_.size() - pos_; }
  const std::uint8_t* here() const noexcept { return m_.data() + pos_; }

  template <typename T>
  bool read(T& v) {
    const std::size_t a = aligned_ ? sizeof(T) : 1;
    const std::size_t aligned = base_ + (pos_ - base_ + a - 1) / a * a;
    if (aligned > m_.size() || m_.size() - aligned < sizeof(T)) return false;
    std::memcpy(&v, m_.data() + aligned, sizeof(T));
    pos_ = aligned + sizeof(T);
    return true;
  }
  /// A CDR string: u32 length including the NUL, then the bytes.
  bool read_string(std::string& s) {
    std::uint32_t n = 0;
    if (!read(n) || n > remaining()) return false;
    const char* p = reinterpret_cast<const char*>(here());
    s.assign(p, n > 0 && p[n - 1] == '\0' ? n - 1 : n);
    pos_ += n;
    return true;
  }
  bool skip(std::size_t n) {
    if (n > remaining()) return false;
    pos_ += n;
    return true;
  }

 private:
  std::span<const std::uint8_t> m_;
  std::size_t base_;
  std::size_t pos_;
  bool aligned_;
};

/// Bytes after a message's last field: CDR pads a message to 4 bytes (ROS 2),
/// ROS 1 not at all; more means a length or count smaller than the events it
/// precedes, whose rest would be lost unseen.
std::optional<MessageFault> trailing_bytes(const CdrCursor& c, bool ros1, const char* field) {
  const std::size_t allowed = ros1 ? 0 : 3;
  if (c.remaining() <= allowed) return std::nullopt;
  return MessageFault{c.pos(), std::to_string(c.remaining()) + " bytes follow the field '" + field +
                                   "', the message's last (its length or count is too small?)"};
}

/// A stated width or height beyond any camera's (kMaxSensorSide) is corrupt
/// data, not a sensor: it would turn negative as an int.
std::optional<MessageFault> implausible_size(const CdrCursor& c, std::uint32_t width, std::uint32_t height) {
  constexpr auto kMax = static_cast<std::uint32_t>(kMaxSensorSide);
  if (width <= kMax && height <= kMax) return std::nullopt;
  return MessageFault{c.pos(), "height/width " + std::to_string(height) + "/" + std::to_string(width) +
                                   " beyond any camera's (at most " + std::to_string(kMaxSensorSide) +
                                   " px a side)"};
}

MessageFault ends_inside(const CdrCursor& c, const char* field) {
  return MessageFault{c.pos(), std::string("message ends inside its field '") + field + "'"};
}

MessageFault outside(std::size_t at, std::uint32_t x, std::uint32_t y, std::uint32_t width,
                     std::uint32_t height) {
  return MessageFault{at, "event at x=" + std::to_string(x) + " y=" + std::to_string(y) +
                              " outside the " + std::to_string(width) + "x" +
                              std::to_string(height) + " sensor the message states"};
}

bool inside(std::uint32_t x, std::uint32_t y, std::uint32_t width, std::uint32_t height) {
  return width == 0 || (x < width && y < height);
}

std::string_view strip_msg(std::string_view type, std::string& buffer) {
  const std::size_t at = type.find("/msg/");
  if (at == std::string_view::npos) return type;
  buffer = std::string(type.substr(0, at)) + "/" + std::string(type.substr(at + 5));
  return buffer;
}

/// The fault of a payload of 8-byte words whose size is no multiple of 8
/// (at its last, partial word), or none.
std::optional<MessageFault> partial_word_fault(const char* encoding, std::size_t payload_bytes) {
  if (payload_bytes % 8 == 0) return std::nullopt;
  return MessageFault{payload_bytes / 8 * 8, std::string(encoding) + " payload of " + std::to_string(payload_bytes) +
                                                  " bytes, not a multiple of 8"};
}

// The payloads of one 8-byte word per event (mono; libcaer loops itself, as it skips words): `one(word, at,
// event)` decodes the word at byte `at`, or returns the fault that stops the
// message there; the events before a fault stay in `out`.
template <typename DecodeOne>
std::optional<MessageFault> decode_words(const char* encoding, std::span<const std::uint8_t> payload,
                                         std::vector<RosEvent>& out, DecodeOne one) {
  constexpr std::size_t kBytes = 8;
  const std::size_t n = payload.size() / kBytes;
  const std::size_t first = out.size();
  out.resize(first + n);
  RosEvent* dst = out.data() + first;
  for (std::size_t i = 0; i < n; ++i) {
    if (std::optional<MessageFault> fault = one(payload.data() + i * kBytes, i * kBytes, dst[i])) {
      out.resize(first + i);
      return fault;
    }
  }
  return partial_word_fault(encoding, payload.size());
}

}  // namespace

MessageKind message_kind(std::string_view type) {
  std::string buffer;
  const std::string_view t = strip_msg(type, buffer);
  if (t == "event_camera_msgs/EventPacket" || t == "event_array_msgs/EventArray")
    return MessageKind::event_packet;
  // dv_ros_msgs: iniVation's dv-ros driver, the dvs_msgs layout under its own name.
  if (t == "dvs_msgs/EventArray" || t == "prophesee_event_msgs/EventArray" || t == "dv_ros_msgs/EventArray")
    return MessageKind::event_array;
  return MessageKind::not_events;
}

std::string_view known_message_types() {
  return EVLIFE_ROS_EVENT_MESSAGE_TYPES;
}

std::optional<MessageFault> decode_libcaer(std::span<const std::uint8_t> payload, std::uint64_t time_base,
                                           std::uint32_t width, std::uint32_t height, std::vector<RosEvent>& out,
                                           std::uint64_t& invalid_count) {
  constexpr std::size_t kBytes = 8;
  // The 31-bit µs clock, unwrapped within the message the way the other
  // formats' clocks are (wrapping_counter.h): only a drop by more than half
  // its range (17.9 min) is a wrap; a smaller one stays a step back, which
  // the checked reader reports. (Taking every drop for a wrap put a corrupt
  // or zeroed event 35.8 min later, with no error.)
  WrappingCounter<31> clock;
  out.reserve(out.size() + payload.size() / kBytes);
  for (std::size_t at = 0; at + kBytes <= payload.size(); at += kBytes) {
    std::uint32_t data;
    std::int32_t ts;
    std::memcpy(&data, payload.data() + at, 4);
    std::memcpy(&ts, payload.data() + at + 4, 4);
    // libcaer's valid mark (bit 0) clear: an event a filter invalidated, or
    // zeroed bytes; skipped and counted (skipped_record_kinds).
    if ((data & 1u) == 0) {
      ++invalid_count;
      continue;
    }
    const std::uint32_t x = (data >> 17) & 0x7FFFu;
    const std::uint32_t y = (data >> 2) & 0x7FFFu;
    if (ts < 0) return MessageFault{at, "libcaer event with a negative timestamp"};
    if (!inside(x, y, width, height)) return outside(at, x, y, width, height);
    const std::int64_t offset_ns = clock.unwrap(static_cast<std::uint32_t>(ts)) * 1000;  // |.| < 2^31 * 1000 * words
    const bool fits = offset_ns < 0 ? time_base >= static_cast<std::uint64_t>(-offset_ns)
                                    : time_base <= kMaxTimeNs - static_cast<std::uint64_t>(offset_ns);
    if (!fits) return MessageFault{at, "libcaer event time beyond the 64-bit ns range"};
    out.push_back(RosEvent{static_cast<std::int64_t>(time_base) + offset_ns, static_cast<std::uint16_t>(x),
                           static_cast<std::uint16_t>(y), (data & 2u) != 0 ? std::int8_t{1} : std::int8_t{-1}});
  }
  return partial_word_fault("libcaer", payload.size());
}

std::optional<MessageFault> decode_libcaer_cmp(std::span<const std::uint8_t> payload, std::uint64_t time_base,
                                               std::uint32_t width, std::uint32_t height, LibcaerCmpState& state,
                                               std::vector<RosEvent>& out) {
  constexpr std::uint64_t kMaxOffsetNs = ((std::uint64_t{1} << 24) - 1) * 1000;
  if (time_base > kMaxTimeNs - kMaxOffsetNs) return MessageFault{0, "libcaer_cmp time_base beyond the 64-bit ns range"};
  std::uint32_t high = 0, low = 0;  // µs after time_base
  const auto emit = [&](std::size_t at, std::uint32_t x, std::uint32_t y, std::int8_t p) -> std::optional<MessageFault> {
    if (y > 0xFFFFu) return MessageFault{at, "libcaer_cmp vector row " + std::to_string(y) + " beyond any sensor"};
    if (!inside(x, y, width, height)) return outside(at, x, y, width, height);
    out.push_back(RosEvent{static_cast<std::int64_t>(time_base + std::uint64_t{high | low} * 1000),
                           static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), p});
    return std::nullopt;
  };
  for (std::size_t at = 0; at + 1 < payload.size(); at += 2) {
    const auto w = static_cast<std::uint32_t>(payload[at] | (payload[at + 1] << 8));
    const std::uint32_t code = w >> 12, rest = w & 0xFFFu, row = rest & 0x7FFu;
    const std::int8_t polarity = (rest & 0x800u) != 0 ? std::int8_t{1} : std::int8_t{-1};
    switch (code) {
      case 0: high = rest << 12; break;
      case 1: low = rest; break;
      case 2: state.x = static_cast<std::int32_t>(row); break;
      case 3:  // one event; its polarity is its own
        if (state.x < 0) return MessageFault{at, "libcaer_cmp ADDR_Y word before any ADDR_X"};
        if (auto fault = emit(at, static_cast<std::uint32_t>(state.x), row, polarity)) return fault;
        break;
      case 4:  // the base row and polarity of the vectors after it
        state.base_y = static_cast<std::int32_t>(row);
        state.polarity = polarity;
        break;
      case 5:
        if (state.x < 0 || state.base_y < 0)
          return MessageFault{at, "libcaer_cmp VECT_8 word before any ADDR_X and VECT_BASE_Y"};
        for (std::uint32_t bit = 0; bit < 8; ++bit) {
          if ((rest & (1u << bit)) == 0) continue;
          if (auto fault = emit(at, static_cast<std::uint32_t>(state.x), static_cast<std::uint32_t>(state.base_y) + bit,
                                state.polarity))
            return fault;
        }
        state.base_y = std::min(state.base_y + 8, 0x10000);  // beyond any row: faults as outside
        break;
      default:
        return MessageFault{at, "libcaer_cmp word of unknown code " + std::to_string(code)};
    }
  }
  if (payload.size() % 2 != 0)  // after the events of the whole words, as the other decoders
    return MessageFault{payload.size() - 1, "libcaer_cmp payload of " + std::to_string(payload.size()) +
                                                " bytes, not a multiple of 2"};
  return std::nullopt;
}

std::optional<MessageFault> decode_mono(std::span<const std::uint8_t> payload,
                                        std::uint64_t time_base, std::uint32_t width,
                                        std::uint32_t height, std::vector<RosEvent>& out) {
  if (time_base > kMaxTimeNs - 0xFFFFFFFFu) return MessageFault{0, "mono time_base beyond the 64-bit ns range"};
  const auto one = [&](const std::uint8_t* word, std::size_t at, RosEvent& e) -> std::optional<MessageFault> {
    std::uint64_t w;
    std::memcpy(&w, word, 8);
    const auto x = static_cast<std::uint32_t>((w >> 32) & 0xFFFFu);
    const auto y = static_cast<std::uint32_t>((w >> 48) & 0x7FFFu);
    if (!inside(x, y, width, height)) return outside(at, x, y, width, height);
    e = RosEvent{static_cast<std::int64_t>(time_base + (w & 0xFFFFFFFFu)),
                 static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y),
                 (w >> 63) != 0 ? std::int8_t{1} : std::int8_t{-1}};
    return std::nullopt;
  };
  return decode_words("mono", payload, out, one);
}

std::optional<MessageFault> decode_evt3(std::span<const std::uint8_t> payload, Evt3Decoder& decoder,
                                        std::vector<Event>& scratch, std::vector<RosEvent>& out) {
  constexpr std::size_t kChunk = 4096;
  if (scratch.size() < kChunk) scratch.resize(kChunk);
  const std::size_t words = payload.size() / Evt3Decoder::kWordBytes;
  std::size_t done = 0;
  while (done < words) {
    const Evt3Decoder::Result r =
        decoder.decode(payload.data() + done * Evt3Decoder::kWordBytes, words - done, scratch);
    const std::size_t first = out.size();
    out.resize(first + r.events);
    for (std::size_t i = 0; i < r.events; ++i) {
      const Event& e = scratch[i];
      out[first + i] = RosEvent{e.t_us * 1000, e.x, e.y, e.p};
    }
    done += r.words;
    if (r.fault) {
      const std::size_t bad_word = r.fault_began_a_word_before && done > 0 ? done - 1 : done;  // in this payload
      return MessageFault{bad_word * Evt3Decoder::kWordBytes, decoder.fault_message()};
    }
  }
  if (payload.size() % Evt3Decoder::kWordBytes != 0)
    return MessageFault{words * Evt3Decoder::kWordBytes, "evt3 payload of odd length"};
  return std::nullopt;
}

std::optional<MessageFault> MessageDecoder::decode(std::span<const std::uint8_t> message,
                                                   std::vector<RosEvent>& out) {
  out.clear();
  if (serialization_ == Serialization::ros1) {
    return kind_ == MessageKind::event_packet ? decode_packet(message, 0, out) : decode_array(message, 0, out);
  }
  if (message.size() < kEncapsulationBytes)
    return MessageFault{0, "message shorter than its CDR encapsulation header"};
  if (message[0] != 0 || message[1] > 1)
    return MessageFault{0, "not a CDR message (encapsulation " + std::to_string(message[0]) + "," +
                               std::to_string(message[1]) + ")"};
  if (message[1] == 0) return MessageFault{0, "big-endian CDR messages are not supported"};
  return kind_ == MessageKind::event_packet ? decode_packet(message, kEncapsulationBytes, out)
                                            : decode_array(message, kEncapsulationBytes, out);
}

namespace {

/// std_msgs/Header: (ROS 1: u32 seq), stamp (i32 sec, u32 nanosec), string frame_id.
bool skip_header(CdrCursor& c, bool ros1) {
  std::uint32_t seq = 0;
  if (ros1 && !c.read(seq)) return false;
  std::int32_t sec = 0;
  std::uint32_t nanosec = 0;
  std::uint32_t n = 0;
  return c.read(sec) && c.read(nanosec) && c.read(n) && c.skip(n);
}

}  // namespace

std::optional<MessageFault> MessageDecoder::decode_packet(std::span<const std::uint8_t> m,
                                                          std::size_t base,
                                                          std::vector<RosEvent>& out) {
  const bool ros1 = serialization_ == Serialization::ros1;
  CdrCursor c(m, base, !ros1);
  if (!skip_header(c, ros1)) return ends_inside(c, "header");
  if (!c.read(height_) || !c.read(width_)) return ends_inside(c, "height/width");
  if (auto fault = implausible_size(c, width_, height_)) return fault;
  std::uint64_t seq = 0;
  std::uint64_t time_base = 0;
  if (!c.read(seq) || !c.read(time_base)) return ends_inside(c, "seq/time_base");
  if (!c.read_string(encoding_)) return ends_inside(c, "encoding");
  std::uint8_t big_endian = 0;
  std::uint32_t size = 0;
  if (!c.read(big_endian)) return ends_inside(c, "is_bigendian");
  if (!c.read(size)) return ends_inside(c, "events");
  const std::size_t payload_at = c.pos();
  if (size > c.remaining()) {
    return MessageFault{payload_at, "events field of " + std::to_string(size) + " bytes, only " +
                                        std::to_string(c.remaining()) + " left in the message"};
  }
  if (big_endian != 0) return MessageFault{payload_at, "big-endian event payloads are not supported"};
  const std::span<const std::uint8_t> payload(c.here(), size);
  c.skip(size);
  if (auto fault = trailing_bytes(c, ros1, "events")) return fault;
  std::optional<MessageFault> fault;
  if (encoding_ == "evt3") {
    evt3_.set_geometry(width_ == 0 ? 2048u : width_, height_ == 0 ? 2048u : height_);
    fault = decode_evt3(payload, evt3_, evt3_scratch_, out);
  } else if (encoding_ == "libcaer") {
    fault = decode_libcaer(payload, time_base, width_, height_, out, libcaer_invalid_);
  } else if (encoding_ == "mono") {
    fault = decode_mono(payload, time_base, width_, height_, out);
  } else if (encoding_ == "libcaer_cmp") {
    fault = decode_libcaer_cmp(payload, time_base, width_, height_, libcaer_cmp_, out);
  } else {
    return MessageFault{payload_at, "unsupported event encoding '" + encoding_ +
                                        "' (readable: evt3, libcaer, libcaer_cmp, mono)"};
  }
  if (fault) fault->byte_in_message += payload_at;
  return fault;
}

std::optional<MessageFault> MessageDecoder::decode_array(std::span<const std::uint8_t> m,
                                                         std::size_t base,
                                                         std::vector<RosEvent>& out) {
  const bool ros1 = serialization_ == Serialization::ros1;
  CdrCursor c(m, base, !ros1);
  encoding_.clear();
  if (!skip_header(c, ros1)) return ends_inside(c, "header");
  if (!c.read(height_) || !c.read(width_)) return ends_inside(c, "height/width");
  if (auto fault = implausible_size(c, width_, height_)) return fault;
  std::uint32_t n = 0;
  if (!c.read(n)) return ends_inside(c, "events");
  // Each event takes at least 13 bytes: refuse counts the message cannot hold.
  if (n > c.remaining() / 13) {
    return MessageFault{c.pos(), "event count " + std::to_string(n) + " larger than the message holds"};
  }
  out.reserve(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::size_t at = c.pos();
    std::uint16_t x = 0;
    std::uint16_t y = 0;
    std::int32_t sec = 0;
    std::uint32_t nanosec = 0;
    std::uint8_t polarity = 0;
    if (!c.read(x) || !c.read(y) || !c.read(sec) || !c.read(nanosec) || !c.read(polarity))
      return ends_inside(c, "events");
    if (!inside(x, y, width_, height_)) return outside(at, x, y, width_, height_);
    if (sec < 0 || nanosec >= 1'000'000'000u)
      return MessageFault{at, "event time " + std::to_string(sec) + " s " + std::to_string(nanosec) +
                                  " ns is not a valid ROS time"};
    out.push_back(RosEvent{static_cast<std::int64_t>(sec) * 1'000'000'000 + nanosec, x, y,
                           polarity != 0 ? std::int8_t{1} : std::int8_t{-1}});
  }
  return trailing_bytes(c, ros1, "events");
}

std::size_t take_events(const std::vector<RosEvent>& events, std::size_t& next, std::span<Event> out) noexcept {
  const std::size_t k = std::min(out.size(), events.size() - next);
  for (std::size_t i = 0; i < k; ++i) {
    const RosEvent& e = events[next + i];
    out[i] = Event{e.t_ns / 1000, e.x, e.y, e.p};
  }
  next += k;
  return k;
}

}  // namespace evlife::io::ros
