// Shared body of the ROS payload fuzz targets (fuzz_ros_<encoding>.cpp). The
// input: u16 width, u16 height (0 = unstated), u64 time_base (little-endian),
// u8 cut, then the payload. The payload is decoded whole, and again cut in
// two messages at byte 2 × cut (one decoder state across both, as in a bag).
// Findings: a crash or sanitizer report, or a broken contract: an event
// outside the stated sensor, a polarity other than ±1, a negative time, or
// the two decodes disagreeing.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <span>
#include <vector>

#include "ros_messages.h"

namespace evlife::fuzz {

inline void ros_contract_violation(const char* what) {
  std::fprintf(stderr, "evlife fuzz: ROS payload decoder contract broken: %s\n", what);
  std::abort();
}

struct PayloadInput {
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::uint64_t time_base = 0;
  std::size_t cut = 0;
  std::span<const std::uint8_t> payload;
};

inline std::optional<PayloadInput> parse_payload_input(const std::uint8_t* data, std::size_t size) {
  constexpr std::size_t kHead = 13;
  if (size < kHead) return std::nullopt;
  PayloadInput in;
  std::uint16_t w = 0;
  std::uint16_t h = 0;
  std::memcpy(&w, data, 2);
  std::memcpy(&h, data + 2, 2);
  std::memcpy(&in.time_base, data + 4, 8);
  in.width = w;
  in.height = h;
  in.cut = std::size_t{2} * data[12];
  in.payload = std::span<const std::uint8_t>(data + kHead, size - kHead);
  if (in.cut > in.payload.size()) in.cut = in.payload.size();
  return in;
}

/// Checks the decoded events; `width`/`height` 0 = no bound.
inline void check_events(const std::vector<io::ros::RosEvent>& events, std::uint32_t width,
                         std::uint32_t height) {
  for (const io::ros::RosEvent& e : events) {
    if (e.p != 1 && e.p != -1) ros_contract_violation("polarity not +1/-1");
    if (e.t_ns < 0) ros_contract_violation("negative time");
    if (width > 0 && height > 0 && (e.x >= width || e.y >= height))
      ros_contract_violation("event outside the stated sensor");
  }
}

inline bool same_events(const std::vector<io::ros::RosEvent>& a, const std::vector<io::ros::RosEvent>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].t_ns != b[i].t_ns || a[i].x != b[i].x || a[i].y != b[i].y || a[i].p != b[i].p) return false;
  }
  return true;
}


/// One input through an 8-byte-word payload decoder (ros::decode_libcaer;
/// ros::decode_mono through a lambda), `decode(payload, time_base, width,
/// height, out, skipped)` adding the words it skips to `skipped` (libcaer's
/// events without their valid mark), whole: no cut decode is compared, as
/// the clock wraps only inside one message. Checked: the events' contract, a
/// fault inside the payload, and no event lost without a fault or a count.
template <class Decode>
int fuzz_word_payload(const std::uint8_t* data, std::size_t size, Decode decode) {
  const auto in = parse_payload_input(data, size);
  if (!in) return 0;
  std::vector<io::ros::RosEvent> whole;
  std::uint64_t skipped = 0;
  const auto fault = decode(in->payload, in->time_base, in->width, in->height, whole, skipped);
  check_events(whole, in->width, in->height);
  if (fault && fault->byte_in_message > in->payload.size()) ros_contract_violation("fault beyond the payload");
  if (!fault && whole.size() + skipped != in->payload.size() / 8) ros_contract_violation("events lost without a fault");
  return 0;
}

}  // namespace evlife::fuzz
