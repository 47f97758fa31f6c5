#include "evlife/algo/lifetime_estimator.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>

#include "censored_refit.h"
#include "event_rng.h"
#include "plane_draws.h"
#include "plane_fit.h"
#include "stage_clock.h"
#include "time_plane.h"
#include "window_samples.h"

namespace evlife {
namespace {

constexpr std::int64_t kNoPrediction = std::numeric_limits<std::int64_t>::min();
// Events ahead that process(span) prefetches: enough to overlap a DRAM
// access (~100 ns) with the processing of the events before.
constexpr std::size_t kPrefetchDistance = 4;
// The adaptive RANSAC budget by [neighbours][inliers] (iterations_table_).
constexpr std::size_t kIterationsTableEntries = (detail::kMaxNeighbours + 1) * (detail::kMaxNeighbours + 1);
// Fits of fewer samples (new event included) store no timing noise: their
// residual RMS, with fewer than 3 degrees of freedom (n - 3), is too loose an
// estimate (a variance from k degrees of freedom scatters by sqrt(2 / k):
// 141 % at k = 1). Such fits are continuations of 4-5 samples; with them
// storing, fits through 10 Hz/px of background activity widened the window
// medians (window_noise.h) until 75 % of the noise passed in the 5th second
// (LongRecordings.HeavyBackgroundActivityDoesNotRunAway).
constexpr int kMinTimingNoiseSamples = 6;
// std::lround of a value in [-1, 1], without the libm call.
int round_unit(double u) noexcept { return static_cast<int>(u >= 0.5) - static_cast<int>(u <= -0.5); }

// std::llround for |v| < 2^62, without the libm call.
std::int64_t round_to_int64(double v) noexcept {
  return static_cast<std::int64_t>(v + (v >= 0.0 ? 0.5 : -0.5));
}

int ransac_iterations_for(double outlier_fraction, double confidence) {
  const double inlier_pair = (1.0 - outlier_fraction) * (1.0 - outlier_fraction);
  const double k = std::log(1.0 - confidence) / std::log(1.0 - inlier_pair);
  return std::max(1, static_cast<int>(std::ceil(k)));
}

}  // namespace

// The RANSAC iterations that draw an all-inlier pair with ransac_confidence,
// indexed by how many of `count` past events are inliers (precomputed in the
// constructor).
inline const int* LifetimeEstimator::iterations_needed(int count) const noexcept {
  return &iterations_table_[static_cast<std::size_t>(count) * (detail::kMaxNeighbours + 1)];
}

std::string rejected_events_text(const LifetimeStats& stats) {
  std::string text;
  for (const RejectionCounter& c : kRejectionCounters) {
    const std::uint64_t n = stats.*c.count;
    if (n == 0 && !c.said_when_zero) continue;
    text += (text.empty() ? "" : ", ") + std::to_string(n) + " " + c.text;
  }
  return text;
}

std::uint64_t LifetimeEstimator::state_bytes(SensorSize sensor) noexcept {
  const auto pixels = 2 * static_cast<std::size_t>(sensor.pixel_count());  // both polarities
  // As the constructor allocates: each plane rounded as allocate_large rounds
  // it (it read 3.5 MB for the 5.2 MB a 240 x 180 sensor takes), and the table.
  return detail::large_allocation_bytes((pixels + detail::kGatherOverreadPixels) * sizeof(SurfacePixel)) +
         detail::large_allocation_bytes(pixels * sizeof(PixelState)) +
         detail::large_allocation_bytes(pixels * sizeof(std::uint8_t)) +  // burst_followers_
         kIterationsTableEntries * sizeof(int);
}

LifetimeEstimator::LifetimeEstimator(const LifetimeOptions& options) : options_(options), bounds_(options.sensor) {
  if (const std::string err = validate_lifetime_options(options); !err.empty()) {
#if defined(__cpp_exceptions)
    throw std::invalid_argument("LifetimeOptions." + err);
#else
    std::abort();  // built without exceptions: use make_lifetime_estimator(), which validates first
#endif
  }
  half_window_ = options_.window_size / 2;
  ransac_iterations_ = ransac_iterations_for(options_.outlier_fraction, options_.ransac_confidence);
  min_support_fraction_ = 1.0 - options_.outlier_fraction;
  max_event_offset2_ = options_.max_event_offset_tolerances * options_.max_event_offset_tolerances;
  // Continuations: the stricter of the two limits (0: none).
  const double continuation_k = options_.continuation_max_event_offset_tolerances;
  continuation_max_event_offset2_ =
      max_event_offset2_ == 0.0 || continuation_k == 0.0 ? std::max(max_event_offset2_, continuation_k * continuation_k)
                                                        : std::min(max_event_offset2_, continuation_k * continuation_k);
  // A span below the window would cut followers the window allows.
  burst_span_lifetimes_ = std::max(options_.burst_span_lifetimes, options_.burst_window_lifetimes);
  // The smallest lifetime the timestamps resolve: a plane rising less than
  // the timestamp jitter (inlier_tolerance_us) across the window's half-width
  // fits a flat surface as well, e.g. a blob whose pixels fire within a few
  // us, or a readout that stamps a row of events with one timestamp.
  min_lifetime_us_ = std::max(options_.inlier_tolerance_us / half_window_, 1.0);
  surface_.resize(2 * static_cast<std::size_t>(options_.sensor.pixel_count()) + detail::kGatherOverreadPixels);
  pixel_state_.resize(2 * static_cast<std::size_t>(options_.sensor.pixel_count()));
  burst_followers_.resize(pixel_state_.size());
  iterations_table_.resize(kIterationsTableEntries);
  for (int count = 1; count <= detail::kMaxNeighbours; ++count) {
    for (int inliers = 0; inliers <= count; ++inliers) {
      const double w = static_cast<double>(inliers) / count;
      int k = ransac_iterations_;
      if (inliers >= count) {
        k = 1;
      } else if (inliers >= 2) {
        k = std::min(k, static_cast<int>(std::ceil(std::log(1.0 - options_.ransac_confidence) /
                                                   std::log(1.0 - w * w))));
      }
      iterations_table_[static_cast<std::size_t>(count) * (detail::kMaxNeighbours + 1) + inliers] = k;
    }
  }
  reset();
}

void LifetimeEstimator::reset() noexcept {
  std::fill(surface_.begin(), surface_.end(), SurfacePixel{detail::kNeverRel, 0.0f});
  epoch_us_.fill(0);
  last_t_us_.fill(std::numeric_limits<std::int64_t>::min());
  std::fill(pixel_state_.begin(), pixel_state_.end(), PixelState{kNoPrediction, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f});
  std::fill(burst_followers_.begin(), burst_followers_.end(), std::uint8_t{0});
  stats_ = LifetimeStats{};
}

std::size_t LifetimeEstimator::process(std::span<const Event> in,
                                       std::span<AugmentedEvent> out) noexcept {
  const std::size_t n = std::min(in.size(), out.size());
  for (std::size_t i = 0; i < n; ++i) {
    if (i + kPrefetchDistance < n) prefetch(in[i + kPrefetchDistance]);
    out[i] = process(in[i]);
  }
  return n;
}

void LifetimeEstimator::prefetch(const Event& e) const noexcept {
  const int W = bounds_.value.width;
  const int H = bounds_.value.height;
  if (e.x >= W || e.y >= H) return;
  const int pol = e.p > 0 ? 1 : 0;
  const int x = e.x;
  const int y = e.y;
  __builtin_prefetch(&pixel_state_[pixel_index(pol, x, y)], 1);
  __builtin_prefetch(&burst_followers_[pixel_index(pol, x, y)], 1);
  // The rows above and below: the next prediction goes to a neighbour (a
  // store that misses the cache stalls; 1280x720: +25 %), where the states
  // exceed the caches (small sensors: -1 %).
  if (pixel_state_.size() * sizeof(PixelState) >= (std::size_t{8} << 20)) {
    for (const int yy : {y - 1, y + 1}) {
      if (yy < 0 || yy >= H) continue;
      __builtin_prefetch(&pixel_state_[pixel_index(pol, std::max(0, x - 1), yy)], 1);
      __builtin_prefetch(&pixel_state_[pixel_index(pol, std::min(W - 1, x + 1), yy)], 1);
    }
  }
  // Every window row: its first and last pixel (a row of 2 * half_window + 1
  // pixels of 8 bytes spans at most two cache lines for N <= 9, three for
  // N <= 15: then also its ninth pixel).
  const int x0 = std::max(0, x - half_window_), x1 = std::min(W - 1, x + half_window_);
  const int y0 = std::max(0, y - half_window_), y1 = std::min(H - 1, y + half_window_);
  const SurfacePixel* row = &surface_[pixel_index(pol, 0, y0)];
  for (int yy = y0; yy <= y1; ++yy, row += W) {
    __builtin_prefetch(row + x0);
    if (x1 - x0 > 8) __builtin_prefetch(row + x0 + 8);
    __builtin_prefetch(row + x1);
  }
}

// RANSAC: candidate planes dt = gx*dx + gy*dy through the origin and two
// sampled past events; support = past events within the time tolerance.
// Tolerance = max(floor, fraction of the candidate's lifetime): timing noise
// of real sensors grows with the lifetime, a fixed floor covers jitter.
// Compared squared: no square root per candidate. Adaptive: the iteration
// budget starts at the count for the expected outlier fraction and shrinks as
// better support is found. (first_gx, first_gy): a candidate to try first,
// (0, 0) for none.
inline detail::PlaneCandidate LifetimeEstimator::best_plane(const detail::WindowSamples& nb, detail::EventRng& rng,
                                                     float tol_floor2, float tol_fraction2, float first_gx,
                                                     float first_gy) const noexcept {
  const int count = nb.count;
  const int* budget = iterations_needed(count);  // [inliers]
  detail::PlaneCandidate best;
  int iterations = ransac_iterations_;
  // The predicted plane, when there is one, is the first candidate: where
  // the edge kept its course it holds every sample, and no pair is drawn.
  if (first_gx != 0.0f || first_gy != 0.0f) {
    best = detail::plane_candidate(nb, first_gx, first_gy, tol_floor2, tol_fraction2);
    iterations = best.support > count ? 0 : std::min(iterations, budget[best.support - 1]);
  }
  return detail::best_of_draws(nb, rng, iterations, budget, tol_floor2, tol_fraction2, best);
}

// Weight of a prior plane that predicted this event with error err_us
// (paper eq. 13, in our units).
inline double LifetimeEstimator::prior_weight(double err_us) const noexcept {
  return options_.lambda_unit_px2 *
         (options_.lambda_offset + options_.lambda_gain * std::exp(-options_.lambda_decay_per_us * err_us));
}

// True when the event at a pixel comes too early or too late for the edge
// whose prediction waits there: it passed without firing here.
inline bool LifetimeEstimator::prediction_expired(const PixelState& state, std::int64_t t_us) const noexcept {
  if (options_.prediction_expiry_lifetimes <= 0.0) return false;
  const double err_us = std::fabs(detail::difference_us(t_us, state.prediction_t_us));
  const double gx = static_cast<double>(state.prediction_gx_us_px);
  const double gy = static_cast<double>(state.prediction_gy_us_px);
  const double lifetime_us = std::sqrt(gx * gx + gy * gy);
  return err_us > std::max(options_.inlier_tolerance_us, options_.prediction_expiry_lifetimes * lifetime_us);
}

// True when an edge estimated at a neighbour predicts this event: its plane
// (arrival time + gradient) passes within the inlier tolerance of (x, y, t).
bool LifetimeEstimator::continues_an_edge(int pol, int x, int y, std::int32_t now_rel, double tol_floor_us,
                                          EdgePrior& prior) const noexcept {
  // Every window pixel is evaluated without a branch on its state (the
  // loads then overlap; "burst here" and "ahead" were branches that
  // mispredicted): a pixel without a burst (lifetime 0) has a zero gradient,
  // so ahead_us is 0 (or NaN) and it never matches, nor does the new event's
  // own pixel (dx = dy = 0).
  const int x0 = std::max(0, x - half_window_), x1 = std::min(options_.sensor.width - 1, x + half_window_);
  const int y0 = std::max(0, y - half_window_), y1 = std::min(options_.sensor.height - 1, y + half_window_);
  const double tol_fraction = options_.inlier_tolerance_lifetime_fraction;
  const auto now_rel_us = static_cast<double>(now_rel);  // 32-bit times: their difference is exact in double
  for (int yy = y0; yy <= y1; ++yy) {
    for (int xx = x0; xx <= x1; ++xx) {
      const std::size_t q = pixel_index(pol, xx, yy);
      const PixelState& s = pixel_state_[q];
      const double tau_us = static_cast<double>(s.burst_lifetime_us);
      const double tau2_s = tau_us * tau_us * 1e-6;
      const double gx = static_cast<double>(s.burst_vx_px_s) * tau2_s;  // us/px
      const double gy = static_cast<double>(s.burst_vy_px_s) * tau2_s;
      const double ahead_us = gx * (x - xx) + gy * (y - yy);  // > 0: the edge moves from the neighbour here
      // Times relative to the polarity's epoch: their difference is exact
      // (absolute times near 2^62, or Unix time in us, lost up to 1024 us in double).
      const double tol = std::max(tol_floor_us, tol_fraction * tau_us);
      const double err_us = std::fabs(now_rel_us - static_cast<double>(surface_[q].t_rel) - ahead_us);
      if ((ahead_us > 0.0) & (err_us <= tol)) {
        prior = {gx, gy, err_us};
        return true;
      }
    }
  }
  return false;
}

template <typename Pred>
bool LifetimeEstimator::any_upstream(int pol, int x, int y, const PixelState& state, Pred&& pred) const noexcept {
  const auto vx = static_cast<double>(state.burst_vx_px_s);
  const auto vy = static_cast<double>(state.burst_vy_px_s);
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      // Upstream: the edge, moving along v, reached (x + dx, y + dy) first.
      if (vx * dx + vy * dy >= 0.0) continue;
      const int qx = x + dx, qy = y + dy;
      if (qx < 0 || qy < 0 || qx >= options_.sensor.width || qy >= options_.sensor.height) continue;
      if (pred(pixel_index(pol, qx, qy))) return true;
    }
  }
  return false;
}

// True when an event at (x, y) comes within the time the pixel's slow
// response can spread its burst (burst_span_timing_noise x the residual RMS
// of the burst's fit) and no pixel upstream of the burst's edge has had a
// newer arrival than this pixel's since: no new edge has come this way. Only
// where that time exceeds the burst span in lifetimes (the pixel's response,
// not the edge's transit, sets the timing): elsewhere a longer window only
// lets background activity after an edge pass (faint texture: 96.7 % of the
// noise labelled noise, 95.5 % without this condition, 96.3 % with it).
// Out of line: off by default, and rare when on (estimator x1.00 on garfield).
[[gnu::cold, gnu::noinline]] bool LifetimeEstimator::slow_response_follower(int pol, int x, int y,
                                                                          const PixelState& state,
                                                                          double since_arrival_us) const noexcept {
  const SurfacePixel& here = surface_[pixel_index(pol, x, y)];
  const auto noise_us = static_cast<double>(here.timing_noise_us);
  const double span_us = options_.burst_span_timing_noise * noise_us;
  if (!(noise_us > 0.0) || !(since_arrival_us <= span_us) ||
      !(span_us > burst_span_lifetimes_ * static_cast<double>(state.burst_lifetime_us))) {
    return false;
  }
  const double newer_us = 2.0 * noise_us + options_.inlier_tolerance_us;
  return !any_upstream(pol, x, y, state, [&](std::size_t q) {
    const std::int32_t q_rel = surface_[q].t_rel;
    return q_rel != detail::kNeverRel && static_cast<double>(std::int64_t{q_rel} - here.t_rel) > newer_us;
  });
}

// True when an event at (x, y), past its burst's follower window, comes
// while the shading ramp of the burst's edge is still seen passing: a
// neighbour upstream holds an estimated burst of the same edge (it arrived
// before this pixel's) that has fired since this pixel's latest event and
// within ramp_follower_upstream_lifetimes of now (ramp_follower_span_lifetimes).
// Out of line: only events past their burst window reach it.
[[gnu::noinline]] bool LifetimeEstimator::ramp_follower(int pol, int x, int y, const PixelState& state,
                                                       double since_arrival_us) const noexcept {
  const SurfacePixel& here = surface_[pixel_index(pol, x, y)];
  const auto arrival_rel = static_cast<double>(here.t_rel);
  const double now_rel = arrival_rel + since_arrival_us;
  const double latest_rel = arrival_rel + static_cast<double>(state.burst_latest_us);
  const double live_us =
      options_.ramp_follower_upstream_lifetimes * static_cast<double>(state.burst_lifetime_us);
  return any_upstream(pol, x, y, state, [&](std::size_t q) {
    const PixelState& upstream = pixel_state_[q];
    const std::int32_t upstream_arrival_rel = surface_[q].t_rel;
    if (!(upstream.burst_lifetime_us > 0.0f) || upstream_arrival_rel == detail::kNeverRel ||
        upstream_arrival_rel >= here.t_rel) {
      return false;  // no estimated burst there, or a newer edge's
    }
    const double upstream_latest_rel =
        static_cast<double>(upstream_arrival_rel) + static_cast<double>(upstream.burst_latest_us);
    return upstream_latest_rel > latest_rel && now_rel - upstream_latest_rel <= live_us;
  });
}

// True when a neighbour upstream (the edge reached it first) holds a burst
// with max_burst_followers followers too, its latest event within the burst
// window of now: the edge's own bursts are that long (a low threshold, a
// high contrast), not this pixel's alone (a hot pixel).
// Out of line: only bursts past max_burst_followers reach it.
[[gnu::cold, gnu::noinline]] bool LifetimeEstimator::long_bursts_upstream(int pol, int x, int y,
                                                                        const PixelState& state,
                                                                        std::int32_t now_rel) const noexcept {
  const double window_us = options_.burst_window_lifetimes * static_cast<double>(state.burst_lifetime_us);
  return any_upstream(pol, x, y, state, [&](std::size_t q) {
    const PixelState& upstream = pixel_state_[q];
    const std::int32_t upstream_arrival_rel = surface_[q].t_rel;
    if (!(upstream.burst_lifetime_us > 0.0f) || upstream_arrival_rel == detail::kNeverRel) return false;
    const double upstream_latest_rel =
        static_cast<double>(upstream_arrival_rel) + static_cast<double>(upstream.burst_latest_us);
    return burst_followers_[q] >= options_.max_burst_followers &&
           static_cast<double>(now_rel) - upstream_latest_rel <= window_us;
  });
}

// True when an event at (x, y) that no fit supports, since_arrival_us after
// the arrival of the estimated burst `burst` there, comes within
// late_follower_upstream_durations x the duration of an upstream neighbour's
// estimated burst of the same edge (arrived before this pixel's), and no
// upstream neighbour holds an arrival newer than this pixel's by more than
// twice the timing noise and the tolerance floor (a new edge reaches them
// first). Out of line: only rejected events shortly after an arrival reach it.
[[gnu::noinline]] bool LifetimeEstimator::late_follower(int pol, int x, int y, const PixelState& burst,
                                                       std::int32_t arrival_rel, double since_arrival_us,
                                                       double timing_noise_us) const noexcept {
  const double f = options_.late_follower_upstream_durations;
  const bool upstream_lasts = any_upstream(pol, x, y, burst, [&](std::size_t q) {
    const PixelState& upstream = pixel_state_[q];
    const std::int32_t q_rel = surface_[q].t_rel;
    return upstream.burst_lifetime_us > 0.0f && q_rel != detail::kNeverRel && q_rel < arrival_rel &&
           since_arrival_us <= f * static_cast<double>(upstream.burst_latest_us);
  });
  if (!upstream_lasts) return false;
  const double newer_us = 2.0 * timing_noise_us + options_.inlier_tolerance_us;
  return !any_upstream(pol, x, y, burst, [&](std::size_t q) {
    const std::int32_t q_rel = surface_[q].t_rel;
    return q_rel != detail::kNeverRel && static_cast<double>(std::int64_t{q_rel} - arrival_rel) > newer_us;
  });
}

// A late event (late_event_keeps_arrival_timing_noise) that no fit supports:
// the surface keeps its burst's arrival, and where the burst has an estimate
// (last_burst_lifetime_us > 0) and late_follower() holds, the event is its
// follower (true; out gets the burst's estimate). Out of line: the rejection
// paths of process() stay small.
[[gnu::noinline]] bool LifetimeEstimator::late_event_rejected(int pol, int x, int y, std::int32_t arrival_rel,
                                                             std::int32_t now_rel, float last_burst_lifetime_us,
                                                             float window_noise_us, AugmentedEvent& out) noexcept {
  const std::size_t self = pixel_index(pol, x, y);
  surface_[self].t_rel = arrival_rel;
  const auto since_arrival_us = static_cast<double>(std::int64_t{now_rel} - arrival_rel);
  PixelState& state = pixel_state_[self];
  if (!(options_.late_follower_upstream_durations > 0.0) || !(last_burst_lifetime_us > 0.0f) ||
      (options_.max_burst_followers != 0 && burst_followers_[self] >= options_.max_burst_followers) ||
      !late_follower(pol, x, y, state, arrival_rel, since_arrival_us, static_cast<double>(window_noise_us))) {
    return false;
  }
  // (The burst's velocity is still in state: only its lifetime was cleared.)
  ++stats_.followers;
  burst_followers_[self] = static_cast<std::uint8_t>(std::min(burst_followers_[self] + 1, 255));
  state.burst_lifetime_us = last_burst_lifetime_us;
  state.burst_latest_us = static_cast<float>(since_arrival_us);
  out.lifetime_us = last_burst_lifetime_us;
  out.vx_px_s = state.burst_vx_px_s;
  out.vy_px_s = state.burst_vy_px_s;
  return true;
}

// Eq. 8's m for a window of which `pixels` count (halfway between them and
// the full window: process()).
inline int LifetimeEstimator::eq8_min_support(int pixels, int full_window) const noexcept {
  return std::max(4, static_cast<int>(std::ceil(min_support_fraction_ * (pixels + full_window) * 0.25 - 1e-9)));
}

// True when `best` has the support of eq. 8 with the window's pixels that
// never fired counted as outside it (the border rule), every supporter fired
// within fresh_region_span_us of the new event, and its own pixel did not
// (since_last_here_us: an edge's arrival; its pixel's later events are a
// burst's followers, not the edge entering) (LifetimeOptions).
// Out of line: only events short of eq. 8's support reach it.
[[gnu::noinline]] bool LifetimeEstimator::supported_in_fresh_region(const detail::WindowSamples& nb,
                                                                    const detail::PlaneCandidate& best,
                                                                    int full_window,
                                                                    double since_last_here_us) const noexcept {
  if (!(options_.fresh_region_span_us > 0.0) || !(since_last_here_us > options_.fresh_region_span_us) ||
      best.support < eq8_min_support(nb.fired + 1, full_window)) {
    return false;
  }
  const auto earliest_us = static_cast<float>(-options_.fresh_region_span_us);
  for (int k = 0; k < nb.count; ++k) {
    const float r = nb.dt_us[k] - best.gx_us_px * nb.dx[k] - best.gy_us_px * nb.dy[k];
    if (r * r <= best.tol2_us2 && nb.dt_us[k] < earliest_us) return false;
  }
  return true;
}

AugmentedEvent LifetimeEstimator::process(const Event& e) noexcept {
  using detail::Stage;
  using detail::stage_end;
  detail::stage_start();
  AugmentedEvent out;
  out.event = e;
  ++stats_.events;
  const int W = bounds_.value.width;
  const int H = bounds_.value.height;
  if (const Rejection why = rejection_of(e, bounds_.value); why != Rejection::none) {
    count_noise(stats_.rejected_counter(why));
    stage_end(Stage::head);
    return out;
  }
  const int pol = e.p > 0 ? 1 : 0;
  // Before anything reads the surface: an earlier time would read as a burst
  // follower (a negative age) and take the estimates of before the jump.
  if (e.t_us < last_t_us_[pol]) {
    count_noise(stats_.time_backwards);
    stage_end(Stage::head);
    return out;
  }
  last_t_us_[pol] = e.t_us;
  const int x = e.x;
  const int y = e.y;
  const std::size_t self = pixel_index(pol, x, y);
  // Each polarity's plane has its own epoch: a jump of one polarity's clock
  // (a corrupt timestamp) moves no time of the other's (both planes moved,
  // and its estimates went wrong, uncounted).
  std::int64_t& epoch_us = epoch_us_[pol];
  if (!detail::fits_epoch(e.t_us, epoch_us)) {
    const std::size_t plane = static_cast<std::size_t>(W) * static_cast<std::size_t>(H);
    epoch_us = detail::rebase(std::span(surface_).subspan(static_cast<std::size_t>(pol) * plane, plane), epoch_us, e.t_us);
  }
  const auto now_rel = static_cast<std::int32_t>(e.t_us - epoch_us);

  // A follower of the burst at this pixel inherits its estimate; the surface
  // keeps the burst's arrival time. Followers chain: each within the burst
  // window of the burst's latest event, all within its span of the arrival,
  // and at most max_burst_followers of them (a hot pixel fires on).
  SurfacePixel& here = surface_[self];
  PixelState& state = pixel_state_[self];
  const auto since_arrival_us = static_cast<double>(std::int64_t{now_rel} - here.t_rel);
  const auto burst_lifetime_us = static_cast<double>(state.burst_lifetime_us);
  const bool within_burst_span =
      since_arrival_us - static_cast<double>(state.burst_latest_us) <=
          options_.burst_window_lifetimes * burst_lifetime_us &&
      since_arrival_us <= burst_span_lifetimes_ * burst_lifetime_us;
  if (state.burst_lifetime_us > 0.0f && options_.burst_window_lifetimes > 0.0 &&
      (within_burst_span ||
       (options_.burst_span_timing_noise > 0.0 && slow_response_follower(pol, x, y, state, since_arrival_us)) ||
       (options_.ramp_follower_span_lifetimes > 0.0 &&
        since_arrival_us <= options_.ramp_follower_span_lifetimes * burst_lifetime_us &&
        ramp_follower(pol, x, y, state, since_arrival_us))) &&
      (options_.max_burst_followers == 0 || burst_followers_[self] < options_.max_burst_followers ||
       long_bursts_upstream(pol, x, y, state, now_rel))) {
    ++stats_.followers;
    burst_followers_[self] = static_cast<std::uint8_t>(std::min(burst_followers_[self] + 1, 255));
    state.burst_latest_us = static_cast<float>(since_arrival_us);
    out.lifetime_us = state.burst_lifetime_us;
    out.vx_px_s = state.burst_vx_px_s;
    out.vy_px_s = state.burst_vy_px_s;
    stage_end(Stage::head);
    return out;
  }
  // The last burst here got no estimate (its followers may yet, below).
  const bool last_burst_unestimated = state.burst_lifetime_us <= 0.0f;
  const float last_burst_lifetime_us = state.burst_lifetime_us;  // late_follower_upstream_durations
  state.burst_lifetime_us = 0.0f;

  // Prediction for this pixel made by an earlier event (paper III-B.2).
  float prior_gx = 0.0f, prior_gy = 0.0f;
  double lambda = 0.0;  // 0: no prior
  if (state.prediction_t_us != kNoPrediction && prediction_expired(state, e.t_us)) {
    state.prediction_t_us = kNoPrediction;
  }
  if (state.prediction_t_us != kNoPrediction) {
    const double err_us = detail::difference_us(e.t_us, state.prediction_t_us);
    out.prediction_error_us = static_cast<float>(err_us);
    ++stats_.predictions;
    if (options_.regularization) {
      prior_gx = state.prediction_gx_us_px;
      prior_gy = state.prediction_gy_us_px;
      lambda = prior_weight(std::fabs(err_us));
    }
    state.prediction_t_us = kNoPrediction;  // a prediction is for the next event only
  }

  stage_end(Stage::head);

  // Gather the window's past events (the part of the window inside the sensor).
  const int x0 = std::max(0, x - half_window_), x1 = std::min(W - 1, x + half_window_);
  const int y0 = std::max(0, y - half_window_), y1 = std::min(H - 1, y + half_window_);
  const int window_pixels = (x1 - x0 + 1) * (y1 - y0 + 1);
  detail::WindowSamples nb;
  float window_noise_us = 0.0f;  // the timing noise the window's fits observed (window_noise.h)
  const std::int32_t previous_rel = here.t_rel;  // the last burst's arrival here
  // The window's pixels but the new event's own, and of them only the newer
  // half (paper Fig. 6): older events belong to an earlier edge, newer ones
  // do not exist yet.
  nb.gather_newest(&surface_[pixel_index(pol, 0, 0)], static_cast<std::size_t>(W), x, y, x0, x1, y0, y1,
                   options_.window_size, now_rel, (window_pixels - 1) / 2, window_noise_us);
  here.t_rel = now_rel;
  // A late event of the burst here (late_event_keeps_arrival_timing_noise):
  // the surface keeps the burst's arrival. Not at a pixel whose burst has had
  // max_burst_followers (a hot pixel: 1 kHz, 1e-3 of the pixels, noise
  // labelled noise 97.00 -> 96.90 % with it, 97.03 % without, k = 15, f = 1.5).
  const bool late_event =
      options_.late_event_keeps_arrival_timing_noise > 0.0 && previous_rel != detail::kNeverRel &&
      previous_rel <= now_rel &&
      static_cast<double>(std::int64_t{now_rel} - previous_rel) <=
          options_.late_event_keeps_arrival_timing_noise * static_cast<double>(window_noise_us) &&
      window_noise_us > 0.0f &&
      (options_.max_burst_followers == 0 || burst_followers_[self] < options_.max_burst_followers);
  // Labels the event noise, unless it is a late event that follows its burst.
  const auto reject = [&](std::uint64_t& reason) noexcept {
    if (late_event &&
        late_event_rejected(pol, x, y, previous_rel, now_rel, last_burst_lifetime_us, window_noise_us, out)) {
      return;
    }
    count_noise(reason);
  };
  stage_end(Stage::gather);
  nb.pad();
  stage_end(Stage::select);
  const int count = nb.count;
  // Minimum support m = (1 - eps) * N^2 / 2 (eq. 8), counting the new event.
  // Near the border only part of the window exists: there m is taken halfway
  // between the clipped and the full window, because few samples fit a random
  // plane easily (with the clipped m alone, the test
  // BorderEventLongAfterEdgePassedIsNoise rejects only 56 of 114 late events).
  // At least 4: two past events define a plane through the new event exactly,
  // only a third one tests it (with eq. 8's m = 3 at N = 3 every event with
  // two past neighbours passed: 98 % of stripes.mat, lifetimes 1.8x too long).
  const int full_window = options_.window_size * options_.window_size;
  const int min_support = eq8_min_support(window_pixels, full_window);
  const int min_continuation_support =
      options_.continuation_min_support > 0 ? std::min(min_support, options_.continuation_min_support + 1) : min_support;
  if (count + 1 < min_continuation_support) {
    reject(stats_.noise_few_samples);
    return out;
  }

  // The RANSAC tolerance's floor: the sensor's timing noise, at least inlier_tolerance_us, else
  // a multiple of the residual scale the fits around this pixel observed
  // (latency jitter grows to hundreds of us in dim light).
  const auto timing_noise_us = static_cast<double>(window_noise_us);
  const double tol_floor_us =
      std::max(options_.inlier_tolerance_us, options_.inlier_tolerance_residual_factor * timing_noise_us);
  const auto tol_floor2 = static_cast<float>(tol_floor_us * tol_floor_us);
  const float tol_fraction2 = static_cast<float>(options_.inlier_tolerance_lifetime_fraction *
                                                 options_.inlier_tolerance_lifetime_fraction);
  detail::EventRng rng(options_.seed, e);
  detail::PlaneCandidate best = best_plane(nb, rng, tol_floor2, tol_fraction2, prior_gx, prior_gy);
  stage_end(Stage::ransac);
  // Where the plane passes at this pixel: the new event, or the arrival of
  // the burst it follows (below).
  std::int32_t anchor_rel = now_rel;
  double max_offset2 = max_event_offset2_;  // in squared tolerances; 0: no check
  if (best.support < min_support) {
    // Too little support to start an edge: accept the event only where an
    // edge upstream predicts it, and let that edge's plane regularize the
    // fit of the few samples (as a prediction does, eq. 12-13).
    EdgePrior upstream;
    const bool continued =
        best.support >= min_continuation_support && continues_an_edge(pol, x, y, now_rel, tol_floor_us, upstream);
    // Else it may follow a burst here whose first event came too early in
    // the edge's passage to be estimated (its neighbours had not fired yet):
    // the plane through that arrival, with the samples there are now.
    // Else, and failing that, it may be an edge entering a fresh region with
    // its own plane (supported_in_fresh_region()).
    const double since_last_here_us = previous_rel == detail::kNeverRel
                                          ? std::numeric_limits<double>::infinity()
                                          : static_cast<double>(std::int64_t{now_rel} - previous_rel);
    const bool own_fresh = !continued && supported_in_fresh_region(nb, best, full_window, since_last_here_us);
    bool supported = continued || own_fresh;
    if (!continued && last_burst_unestimated && options_.burst_window_lifetimes > 0.0 &&
        previous_rel != detail::kNeverRel && previous_rel < now_rel) {
      const detail::PlaneCandidate own = best;
      float own_dt_us[detail::kSampleCapacity];  // to go back to the own plane's samples
      if (own_fresh) std::copy(nb.dt_us, nb.dt_us + nb.count, own_dt_us);
      nb.shift_times(static_cast<float>(std::int64_t{now_rel} - previous_rel));
      best = best_plane(nb, rng, tol_floor2, tol_fraction2);
      anchor_rel = previous_rel;
      if (best.support < min_support && own_fresh) {
        std::copy(own_dt_us, own_dt_us + nb.count, nb.dt_us);
        best = own;
        anchor_rel = now_rel;
      }
      supported = best.support >= min_support || own_fresh;
    }
    if (!supported) {
      reject(stats_.noise_unsupported);
      stage_end(Stage::continuation);
      return out;
    }
    if (continued) {
      max_offset2 = continuation_max_event_offset2_;
      // The upstream edge's plane predicted this event; the best draw had
      // too little support to start an edge. Where the upstream plane holds
      // as many samples as that draw, refit its inliers: one estimated edge
      // is better evidence than a plane through a few jittered samples
      // (pixel model: shares +0.0-1.5 points, p90 errors lower; garfield.mat
      // +1.1 points).
      const detail::PlaneCandidate along_upstream =
          detail::plane_candidate(nb, static_cast<float>(upstream.gx_us_px),
                                  static_cast<float>(upstream.gy_us_px), tol_floor2, tol_fraction2);
      if (along_upstream.support >= best.support) best = along_upstream;
      if (lambda == 0.0) {
        prior_gx = static_cast<float>(upstream.gx_us_px);
        prior_gy = static_cast<float>(upstream.gy_us_px);
        lambda = prior_weight(upstream.err_us);
      }
    }
    stage_end(Stage::continuation);
  }

  // Least-squares refit on the inliers and the anchor: dt = c + g . dp,
  // regularized towards the predicted gradient (eq. 12).
  detail::PlaneFit fit;
  fit.add(0.0, 0.0, 0.0);  // the anchor: the new event or its burst's arrival
  fit.add_inliers(nb, best.gx_us_px, best.gy_us_px, best.tol2_us2);
  Eigen::Vector2d g = Eigen::Vector2d::Zero();  // set by solve(); zero keeps -Wmaybe-uninitialized quiet
  const bool solved = fit.solve(lambda, Eigen::Vector2d(prior_gx, prior_gy), g);
  // The inliers' own plane must hold the new event too (max_event_offset_tolerances,
  // continuation_max_event_offset_tolerances).
  if (double offset_us = 0.0;
      solved && max_offset2 > 0.0 &&
      fit.offset_without_anchor(lambda, Eigen::Vector2d(prior_gx, prior_gy), offset_us) &&
      offset_us * offset_us > max_offset2 * static_cast<double>(best.tol2_us2)) {
    reject(stats_.noise_unsupported);
    stage_end(Stage::refit);
    return out;
  }
  double lifetime_us = g.norm();
  const double rms_us = fit.residual_rms(g);  // -1: too few samples to tell
  // A follower comes at most burst_window_lifetimes after its burst's arrival.
  if (anchor_rel != now_rel &&
      !(static_cast<double>(std::int64_t{now_rel} - anchor_rel) <= options_.burst_window_lifetimes * lifetime_us)) {
    reject(stats_.noise_unsupported);
    stage_end(Stage::refit);
    return out;
  }
  if (!solved || !std::isfinite(lifetime_us) || lifetime_us < min_lifetime_us_ ||
      lifetime_us > options_.max_lifetime_us) {
    reject(stats_.noise_unresolved);
    stage_end(Stage::refit);
    return out;
  }
  // The lifetime along the plane's direction without the samples causality
  // censors (censored_refit.h); both must be resolved.
  const Eigen::Vector2d u = g * (1.0 / lifetime_us);
  detail::CensoredRefit censored;
  // (Censoring is relative to the new event: not for a burst's arrival.)
  if (options_.skip_censored_samples && timing_noise_us > 0.0 && anchor_rel == now_rel) {
    const double prior_along_u = u.x() * static_cast<double>(prior_gx) + u.y() * static_cast<double>(prior_gy);
    censored = detail::refit_without_censored(nb, best.gx_us_px, best.gy_us_px, best.tol2_us2, u.x(), u.y(),
                                              lifetime_us, options_.censoring_noise_factor * timing_noise_us,
                                              lambda, prior_along_u, options_.max_lifetime_standard_error);
  }
  if (!fit.lifetime_within(g, lambda, rms_us, options_.max_lifetime_standard_error) ||
      (censored.refitted && !censored.resolved)) {
    reject(stats_.noise_unresolved);
    stage_end(Stage::refit);
    return out;
  }
  if (censored.refitted && std::isfinite(censored.lifetime_us) && censored.lifetime_us >= min_lifetime_us_ &&
      censored.lifetime_us <= options_.max_lifetime_us) {
    lifetime_us = censored.lifetime_us;
    g = u * lifetime_us;
  }
  const double gx = g.x(), gy = g.y();
  const double g2 = lifetime_us * lifetime_us;

  stage_end(Stage::refit);
  out.lifetime_us = static_cast<float>(lifetime_us);
  out.vx_px_s = static_cast<float>(gx / g2 * 1e6);
  out.vy_px_s = static_cast<float>(gy / g2 * 1e6);
  if (late_event && anchor_rel == now_rel) anchor_rel = previous_rel;
  state.burst_lifetime_us = out.lifetime_us;
  state.burst_latest_us = static_cast<float>(std::int64_t{now_rel} - anchor_rel);
  burst_followers_[self] = 0;
  state.burst_vx_px_s = out.vx_px_s;
  state.burst_vy_px_s = out.vy_px_s;
  here.timing_noise_us = best.support >= kMinTimingNoiseSamples ? static_cast<float>(rms_us) : 0.0f;
  here.t_rel = anchor_rel;  // a follower keeps its burst's arrival

  // Predict the next event at the neighbour in the direction of motion (the
  // SAE rises along the motion, so along +grad).
  const int qx = x + round_unit(gx / lifetime_us);
  const int qy = y + round_unit(gy / lifetime_us);
  if (qx >= 0 && qy >= 0 && qx < W && qy < H && (qx != x || qy != y)) {
    PixelState& next = pixel_state_[pixel_index(pol, qx, qy)];
    next.prediction_t_us = epoch_us_[pol] + anchor_rel + round_to_int64(gx * (qx - x) + gy * (qy - y));
    next.prediction_gx_us_px = static_cast<float>(gx);
    next.prediction_gy_us_px = static_cast<float>(gy);
  }
  stage_end(Stage::tail);
  return out;
}

}  // namespace evlife
