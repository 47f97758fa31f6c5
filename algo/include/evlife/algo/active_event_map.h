// The events that are active at an instant (paper Sections I and III-B.3):
// the sharp edge image, as data. An event is active from its timestamp until
// timestamp + lifetime; per pixel the latest event replaces older ones; noise
// (lifetime 0) is never stored. Edge thinning: a new event with velocity v
// expires the event of the same polarity at the neighbouring pixel in -v
// direction (the pixel the edge has just left), so an accelerating edge
// (whose lifetimes are overestimated) does not smear.
//
// Usage along a recording: feed() the augmented events in time order up to t,
// then read the state at any t >= last_fed_t_us(): is_active() per pixel,
// active_pixels() as a list, lifetime_image() as a dense image. Moving on to
// a later t only feeds the new events: the history is never re-scanned. To
// look at an earlier t, reset() and feed again from the start.
//
// Fixed memory: every buffer is allocated once in the constructor; feed(),
// the queries and reset() never allocate, lock or throw (tested:
// NoAllocation.ActiveEventMapFeedAndQueriesAllocateNothing). No threads, I/O
// or OpenCV: flight software links evlife::algo alone
// (algo/example/minimal_embedding.cpp). render/ paints from this map.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "evlife/algo/detail/reset_on_move.h"
#include "evlife/algo/event.h"

namespace evlife {

/// What feed() has seen.
struct ActiveEventMapStats {
  std::uint64_t fed = 0;            ///< events given to feed()
  std::uint64_t stored = 0;         ///< events that became the latest of their pixel
  std::uint64_t noise = 0;          ///< lifetime 0: never active
  std::uint64_t out_of_sensor = 0;  ///< coordinates outside the sensor: ignored
  std::uint64_t late = 0;           ///< older than the pixel's current event, or than the map's time range: ignored
  std::uint64_t time_out_of_range = 0;  ///< |t| > kMaxEventTimeUs (event.h): ignored
  std::uint64_t thinned = 0;        ///< neighbours expired by edge thinning
};

/// One pixel holding an active event (active_pixels()).
struct ActivePixel {
  std::int64_t t_us = 0;      ///< timestamp of the event
  std::uint16_t x = 0;
  std::uint16_t y = 0;
  std::int8_t polarity = 0;   ///< +1 or -1
  float lifetime_us = 0.0f;   ///< > 0
  float vx_px_s = 0.0f;       ///< normal velocity of the edge, pixels per second
  float vy_px_s = 0.0f;
};

class ActiveEventMap {
 public:
  /// Largest sensor side accepted.
  static constexpr int kMaxSide = 16384;
  /// True when the constructor accepts `sensor` (1..kMaxSide each way).
  static constexpr bool fits(SensorSize sensor) noexcept {
    return sensor.width >= 1 && sensor.height >= 1 && sensor.width <= kMaxSide &&
           sensor.height <= kMaxSide;
  }

  /// Allocates the per-pixel state (25 bytes a pixel). A sensor that
  /// does not fit() throws std::invalid_argument, or aborts in a build without
  /// exceptions (check fits() first there).
  explicit ActiveEventMap(SensorSize sensor, bool edge_thinning = true);

  /// Adds one augmented event. Events should come in non-decreasing time; one
  /// older than the map's 32-bit range, which reaches 45 to 62 min back from
  /// its newest (the range moves in steps), is counted late and ignored.
  void feed(const AugmentedEvent& a) noexcept;
  void feed(std::span<const AugmentedEvent> events) noexcept {
    for (const auto& a : events) feed(a);
  }

  /// Forgets every event (keeps sensor and options).
  void reset() noexcept;

  /// True when pixel (x, y), inside sensor(), holds an event active at t_us.
  /// Valid for t_us >= last_fed_t_us() (later events would not have been fed yet).
  bool is_active(int x, int y, std::int64_t t_us) const noexcept {
    return is_active(index(x, y), t_us);
  }
  /// Same, by linear pixel index y * width + x.
  bool is_active(std::size_t i, std::int64_t t_us) const noexcept {
    return relative_time(t_us) < static_cast<std::int64_t>(expire_rel_[i]);
  }

  /// Lifetime, polarity, velocity and time of the latest event stored at a pixel.
  float lifetime_us(std::size_t i) const noexcept { return lifetime_us_[i]; }
  std::int8_t polarity(std::size_t i) const noexcept { return polarity_[i]; }
  float vx_px_s(std::size_t i) const noexcept { return vx_px_s_[i]; }
  float vy_px_s(std::size_t i) const noexcept { return vy_px_s_[i]; }
  std::int64_t t_us(std::size_t i) const noexcept { return t_us_[i]; }

  /// Number of pixels active at t_us; O(sensor pixels).
  std::size_t count_active(std::int64_t t_us) const noexcept;

  /// The pixels active at t_us, in row-major order, written into `out` (up to
  /// out.size() of them). Returns how many are active, which may exceed
  /// out.size(): then only the first out.size() were written. O(sensor pixels).
  std::size_t active_pixels(std::int64_t t_us, std::span<ActivePixel> out) const noexcept;

  /// Dense image (index y * width + x): the lifetime in microseconds of the
  /// pixel's active event, 0 where none is active at t_us. Writes the first
  /// min(out.size(), pixel count) pixels.
  void lifetime_image(std::int64_t t_us, std::span<float> out) const noexcept;

  /// Raw expiry map (y * width + x): expiry time in microseconds relative
  /// to epoch_us(); kNeverRel = nothing stored. A pixel is active at t when
  /// relative_time(t) < its entry. 32-bit so that sampling a frame reads
  /// half the memory; the epoch moves forward every ~9 minutes of recording.
  std::span<const std::int32_t> expire_map() const noexcept { return expire_rel_; }
  std::int64_t epoch_us() const noexcept { return epoch_us_; }
  /// t - epoch, saturated into the int32 range (so comparisons stay exact),
  /// for any t (the difference is taken without overflow).
  std::int64_t relative_time(std::int64_t t_us) const noexcept {
    std::int64_t r = 0;
    if (__builtin_sub_overflow(t_us, epoch_us_, &r)) return t_us < 0 ? kNeverRel : kMaxRel;
    return r < kNeverRel ? kNeverRel : (r > kMaxRel ? kMaxRel : r);
  }

  SensorSize sensor() const noexcept { return sensor_.value; }
  bool edge_thinning() const noexcept { return edge_thinning_; }
  std::int64_t last_fed_t_us() const noexcept { return last_fed_t_us_; }
  const ActiveEventMapStats& stats() const noexcept { return stats_; }

  static constexpr std::int64_t kNever = std::numeric_limits<std::int64_t>::min();
  static constexpr std::int32_t kNeverRel = std::numeric_limits<std::int32_t>::min();
  static constexpr std::int32_t kMaxRel = std::numeric_limits<std::int32_t>::max();
  /// Longest lifetime kept exactly (~9 min); longer ones are cut to this.
  static constexpr std::int64_t kMaxLifetimeUs = std::int64_t{1} << 29;

 private:
  std::size_t index(int x, int y) const noexcept {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(sensor_.value.width) +
           static_cast<std::size_t>(x);
  }
  void rebase(std::int64_t t_us) noexcept;

  detail::ResetOnMove<SensorSize> sensor_;  // 0 x 0 once moved from (its planes are gone)
  bool edge_thinning_;
  std::int64_t last_fed_t_us_ = kNever;
  ActiveEventMapStats stats_;

  // Structure of arrays: sampling reads only expire_rel_ for inactive pixels.
  std::int64_t epoch_us_ = 0;
  bool has_epoch_ = false;
  std::vector<std::int32_t> expire_rel_;  // event time + lifetime - epoch; kNeverRel when empty
  std::vector<std::int64_t> t_us_;       // time of the stored event
  std::vector<float> lifetime_us_;
  std::vector<float> vx_px_s_;
  std::vector<float> vy_px_s_;
  std::vector<std::int8_t> polarity_;
};

}  // namespace evlife
