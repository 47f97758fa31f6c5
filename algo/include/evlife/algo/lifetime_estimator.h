// The event lifetime estimator (Mueggler et al., ICRA 2015, Section III).
// Per polarity: a Surface of Active Events, a RANSAC plane fit over the newer
// half of the N x N window, a least-squares refit regularized towards the
// predicted plane, lifetime tau = |grad Sigma| and velocity
// v = grad Sigma / |grad Sigma|^2.
//
// All memory is allocated in the constructor. process() never allocates,
// locks, logs or throws; it is deterministic for given options and input.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "evlife/algo/detail/large_page_allocator.h"
#include "evlife/algo/detail/reset_on_move.h"
#include "evlife/algo/event.h"
#include "evlife/algo/lifetime_options.h"

namespace evlife {
namespace detail {
struct WindowSamples;
struct PlaneCandidate;
class EventRng;
}  // namespace detail

/// Why process() rejects an event unexamined (labelled noise and counted), in
/// the order it checks; `none`: the event is estimated. rejection_of() checks
/// the event alone; time_backwards needs the estimator's past (process()).
enum class Rejection : std::uint8_t { none, out_of_sensor, time_out_of_range, bad_polarity, time_backwards };

constexpr Rejection rejection_of(const Event& e, SensorSize sensor) noexcept {
  if (!sensor.contains(e.x, e.y)) return Rejection::out_of_sensor;
  if (!within_event_time_range(e.t_us)) return Rejection::time_out_of_range;
  if (e.p != 1 && e.p != -1) return Rejection::bad_polarity;
  return Rejection::none;
}

/// Counters of what process() has seen (cheap, updated per event).
struct LifetimeStats {
  std::uint64_t events = 0;
  std::uint64_t noise = 0;             ///< events given lifetime 0: the reasons below, and the rejected
  std::uint64_t noise_few_samples = 0; ///< noise: too few past events in the window to test a plane
  std::uint64_t noise_unsupported = 0; ///< noise: no plane with enough support, no edge to continue
  std::uint64_t noise_unresolved = 0;  ///< noise: the fitted lifetime is implausible or too uncertain
  std::uint64_t predictions = 0;       ///< events that had a prediction
  std::uint64_t followers = 0;         ///< events that inherited their burst's estimate
  std::uint64_t out_of_sensor = 0;     ///< rejected: coordinates outside the sensor
  std::uint64_t bad_polarity = 0;      ///< rejected: p not +1/-1
  std::uint64_t time_out_of_range = 0; ///< rejected: |t| > kMaxEventTimeUs (event.h)
  std::uint64_t time_backwards = 0;    ///< rejected: earlier than the last event of its polarity

  /// Events labelled noise unexamined: the four counters above.
  std::uint64_t rejected() const noexcept;
  /// The counter of a rejection (not `none`).
  std::uint64_t& rejected_counter(Rejection why) noexcept;
};

/// A rejection's counter, its name (Python's dicts: LifetimeEstimator.stats,
/// process_file's 'rejected') and its words in the reports: the one list of
/// them, in the order they are reported.
struct RejectionCounter {
  Rejection why;
  const char* name;
  std::uint64_t LifetimeStats::*count;
  const char* text;     ///< "N <text>" in rejected_events_text
  bool said_when_zero;  ///< time going backwards is said only when there is any
};
inline constexpr std::array<RejectionCounter, 4> kRejectionCounters{{
    {Rejection::out_of_sensor, "out_of_sensor", &LifetimeStats::out_of_sensor, "outside the sensor", true},
    {Rejection::bad_polarity, "bad_polarity", &LifetimeStats::bad_polarity, "bad polarity", true},
    {Rejection::time_out_of_range, "time_out_of_range", &LifetimeStats::time_out_of_range, "time beyond +-2^62 us",
     true},
    {Rejection::time_backwards, "time_backwards", &LifetimeStats::time_backwards, "time going backwards", false},
}};

inline std::uint64_t LifetimeStats::rejected() const noexcept {
  std::uint64_t n = 0;
  for (const RejectionCounter& c : kRejectionCounters) n += this->*c.count;
  return n;
}

inline std::uint64_t& LifetimeStats::rejected_counter(Rejection why) noexcept {
  for (const RejectionCounter& c : kRejectionCounters) {
    if (c.why == why) return this->*c.count;
  }
  return time_out_of_range;  // not reached: every rejection but `none` is listed
}

/// "N outside the sensor, N bad polarity, N time beyond +-2^62 us" (and ", N
/// time going backwards" when there are any): the rejected events, as `evlife
/// process` and Python's evlife.process report them.
std::string rejected_events_text(const LifetimeStats& stats);


class LifetimeEstimator {
 public:
  /// Throws std::invalid_argument (naming the field) on invalid options; a
  /// library built without exceptions (EVLIFE_ALGO_NO_EXCEPTIONS, defined for
  /// the code built against it) aborts instead: validate with
  /// make_lifetime_estimator() (make_lifetime_estimator.h).
  explicit LifetimeEstimator(const LifetimeOptions& options);

  /// Estimates the lifetime and velocity of one event. Events must arrive in
  /// non-decreasing time per polarity; an out-of-sensor event, a bad polarity,
  /// a time beyond kMaxEventTimeUs or one earlier than the last event of its
  /// polarity (a camera's clock restarted: call reset()) is returned as noise
  /// and counted, never read out of bounds. (A moved-from estimator counts
  /// every event out_of_sensor.)
  ///
  /// Its time is bounded by the window and options, but for one event per
  /// 2^30 us (~18 min) of recording per polarity, and the first after a jump
  /// in time of that size: that event moves its polarity's 32-bit surface
  /// epoch, O(pixels) (algo/src/time_plane.h; 1.4 ms for both polarities'
  /// planes on 1280x720 in a helper's measurement, before each had its own).
  AugmentedEvent process(const Event& event) noexcept;

  /// Batch form: out[i] = process(in[i]) for i < min(in.size(), out.size()).
  /// Returns the number of events processed.
  std::size_t process(std::span<const Event> in, std::span<AugmentedEvent> out) noexcept;

  /// Hint only (no effect on results): starts loading the memory that
  /// process(event) will touch, so that a caller holding a batch can issue it
  /// a few events ahead and overlap the cache misses of large sensors.
  void prefetch(const Event& event) const noexcept;

  /// Forgets all history (SAE, predictions and stats(): read the counts you
  /// keep first); keeps the options.
  void reset() noexcept;

  const LifetimeOptions& options() const noexcept { return options_; }
  const LifetimeStats& stats() const noexcept { return stats_; }

  /// Bytes an estimator for `sensor` allocates: both polarities' surfaces
  /// and pixel states (~82 per pixel; planes of 2 MiB or more in whole 2 MiB
  /// pages) and its RANSAC table (202 KB): for a caller to weigh against the
  /// memory it has before constructing one.
  static std::uint64_t state_bytes(SensorSize sensor) noexcept;

 private:
  // What process() reads and writes at the new event's own pixel only, in
  // one cache line (32 bytes, aligned): the prediction made for it by a
  // neighbour's event (time and gradient of the predicted plane;
  // t_us == kNoPrediction: none) and the estimate of the burst now here
  // (inherited by its followers; lifetime 0 = none) with its latest event.
  struct alignas(32) PixelState {
    std::int64_t prediction_t_us;
    float prediction_gx_us_px;
    float prediction_gy_us_px;
    float burst_vx_px_s;
    float burst_vy_px_s;
    float burst_lifetime_us;
    float burst_latest_us;  // the burst's latest event, us after its arrival
  };
  std::size_t pixel_index(int polarity_index, int x, int y) const noexcept {
    return (static_cast<std::size_t>(polarity_index) * static_cast<std::size_t>(bounds_.value.height) +
            static_cast<std::size_t>(y)) * static_cast<std::size_t>(bounds_.value.width) +
           static_cast<std::size_t>(x);
  }

  const int* iterations_needed(int count) const noexcept;
  // The plane of an edge upstream that predicted an event, and its error.
  struct EdgePrior {
    double gx_us_px = 0.0;
    double gy_us_px = 0.0;
    double err_us = 0.0;
  };
  // The RANSAC plane dt = gx*dx + gy*dy through the origin with the most
  // supporters (the origin included), and its squared inlier tolerance.
  detail::PlaneCandidate best_plane(const detail::WindowSamples& nb, detail::EventRng& rng, float tol_floor2,
                                    float tol_fraction2, float first_gx = 0.0f,
                                    float first_gy = 0.0f) const noexcept;
  // An event labelled noise, counted with its reason (a LifetimeStats field).
  void count_noise(std::uint64_t& reason) noexcept {
    ++stats_.noise;
    ++reason;
  }
  double prior_weight(double err_us) const noexcept;
  bool prediction_expired(const PixelState& state, std::int64_t t_us) const noexcept;
  bool slow_response_follower(int pol, int x, int y, const PixelState& state,
                              double since_arrival_us) const noexcept;
  bool ramp_follower(int pol, int x, int y, const PixelState& state, double since_arrival_us) const noexcept;
  bool long_bursts_upstream(int pol, int x, int y, const PixelState& state, std::int32_t now_rel) const noexcept;
  bool late_follower(int pol, int x, int y, const PixelState& burst, std::int32_t arrival_rel, double since_arrival_us,
                     double timing_noise_us) const noexcept;
  bool late_event_rejected(int pol, int x, int y, std::int32_t arrival_rel, std::int32_t now_rel,
                           float last_burst_lifetime_us, float window_noise_us, AugmentedEvent& out) noexcept;
  // True when pred(q) holds at a neighbour q (pixel index) of (x, y) upstream
  // of the motion of the burst in `state`: where its edge came from.
  template <typename Pred>
  bool any_upstream(int pol, int x, int y, const PixelState& state, Pred&& pred) const noexcept;
  int eq8_min_support(int pixels, int full_window) const noexcept;
  bool supported_in_fresh_region(const detail::WindowSamples& nb, const detail::PlaneCandidate& best,
                                 int full_window, double since_last_here_us) const noexcept;
  bool continues_an_edge(int pol, int x, int y, std::int32_t now_rel, double tol_floor_us,
                         EdgePrior& prior) const noexcept;

  LifetimeOptions options_;
  detail::ResetOnMove<SensorSize> bounds_;  // options_.sensor; 0 x 0 once moved from
  LifetimeStats stats_;
  int half_window_ = 2;
  int ransac_iterations_ = 0;
  double min_support_fraction_ = 0.0;
  double max_event_offset2_ = 0.0;  // options_.max_event_offset_tolerances squared
  double continuation_max_event_offset2_ = 0.0;  // the smaller positive of both, squared
  double burst_span_lifetimes_ = 0.0;  // options_.burst_span_lifetimes, at least the burst window
  double min_lifetime_us_ = 0.0;  // see the constructor
  // [polarity][y][x]. What the window gather reads for every pixel, in 8
  // bytes (algo/src/time_plane.h: on a 1280x720 sensor the gather is bound
  // by cache misses); the rest apart.
  struct SurfacePixel {
    std::int32_t t_rel;      // arrival of the edge (burst) here - epoch_us_[polarity]; kNeverRel if none
    float timing_noise_us;   // residual rms of the last accepted fit here (of >= 6 samples); 0 = none
  };
  std::vector<SurfacePixel, detail::LargePageAllocator<SurfacePixel>> surface_;
  std::array<std::int64_t, 2> epoch_us_{};  // [polarity]: that polarity's surface_ times are relative to it
  std::array<std::int64_t, 2> last_t_us_{};  // [polarity]: the latest event's time (time_backwards)
  std::vector<PixelState, detail::LargePageAllocator<PixelState>> pixel_state_;
  // [polarity][y][x]: followers of the burst now at each pixel so far
  // (max_burst_followers; saturates at 255). Apart: PixelState's line is full.
  std::vector<std::uint8_t, detail::LargePageAllocator<std::uint8_t>> burst_followers_;
  std::vector<int> iterations_table_;  // [count][inliers] -> adaptive RANSAC budget
};

}  // namespace evlife
