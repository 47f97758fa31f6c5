// Paces a replay by the event clock: an event of time t is released once
// (t - t_first) / speed has elapsed on the wall clock since the first one.
// speed 0 = as fast as possible (everything is due at once).
#pragma once

#include <cstdint>

namespace evlife::engine {

class EventClockPacer {
 public:
  explicit EventClockPacer(double speed = 0.0) : speed_(speed) {}

  bool paced() const noexcept { return speed_ > 0.0; }
  double speed() const noexcept { return speed_; }

  /// Latest event time (us) due at wall time now_ns; the first call anchors
  /// the event clock at `first_event_t_us`.
  std::int64_t due_until_us(std::int64_t first_event_t_us, std::int64_t now_ns) noexcept {
    if (!anchored_) {
      anchored_ = true;
      t0_us_ = first_event_t_us;
      wall0_ns_ = now_ns;
    }
    if (!paced()) return INT64_MAX;
    return plus_saturated(t0_us_, static_cast<double>(now_ns - wall0_ns_) * 1e-3 * speed_);
  }

  /// Wall time (ns) the event clock was anchored at (anchored only).
  std::int64_t anchor_ns() const noexcept { return wall0_ns_; }

  /// Wall time (ns) at which an event of time t_us becomes due (anchored only).
  std::int64_t due_at_ns(std::int64_t t_us) const noexcept {
    // Event times up to 2^62 apart each way: their difference may exceed int64.
    std::int64_t since_t0_us = 0;
    const double d_us = __builtin_sub_overflow(t_us, t0_us_, &since_t0_us)
                            ? static_cast<double>(t_us) - static_cast<double>(t0_us_)
                            : static_cast<double>(since_t0_us);
    return plus_saturated(wall0_ns_, d_us * 1e3 / speed_);
  }

  /// Wall time (ns) at which the packet holding an event due at `due_ns`
  /// (due_at_ns()) arrives: the end of its slot of `packet_ns` from the
  /// anchor (anchored only; packet_ns > 0). A due time saturated (centuries
  /// ahead) stays INT64_MAX: never, not a wrapped "now".
  std::int64_t packet_arrival_ns(std::int64_t due_ns, std::int64_t packet_ns) const noexcept {
    std::int64_t since = 0, slot_end = 0;
    if (__builtin_sub_overflow(due_ns, wall0_ns_, &since) || since > INT64_MAX - packet_ns ||
        __builtin_add_overflow(wall0_ns_, (since + packet_ns - 1) / packet_ns * packet_ns, &slot_end)) {
      return INT64_MAX;
    }
    return slot_end;
  }

 private:
  // base + offset, held within the int64 range (a gap of centuries, or hours
  // at --realtime=1e-6, overflowed: the event was released at once).
  static std::int64_t plus_saturated(std::int64_t base, double offset) noexcept {
    const double sum = static_cast<double>(base) + offset;
    if (!(sum < 9.2e18)) return INT64_MAX;  // NaN too (it cannot arise: speed_ > 0)
    if (sum <= -9.2e18) return INT64_MIN;
    if (offset > -9e15 && offset < 9e15) return base + static_cast<std::int64_t>(offset);  // exact as before
    return static_cast<std::int64_t>(sum);
  }

  double speed_;
  bool anchored_ = false;
  std::int64_t t0_us_ = 0;
  std::int64_t wall0_ns_ = 0;
};

}  // namespace evlife::engine
