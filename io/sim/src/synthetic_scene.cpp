// Synthetic scene generation: analytic edge-crossing times per pixel, jitter,
// background noise, and the slice-wise sorted stream (see synthetic_scene.h).
#include "evlife/io/synthetic_scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <string>

#include "dvs_pixel_model.h"

namespace evlife::io {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kJitterTruncationSigmas = 4.0;

// splitmix64: tiny, well mixed, identical on every platform (std:: distributions are not).
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }  // [0, 1)
  std::uint64_t below(std::uint64_t n) { return static_cast<std::uint64_t>(uniform() * static_cast<double>(n)); }
  double gaussian() {  // Box-Muller, one value per call (simple, deterministic)
    const double u1 = 1.0 - uniform();  // (0, 1]
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
  }

 private:
  std::uint64_t state_;
};

std::uint64_t slice_seed(std::uint64_t seed, std::int64_t slice) {
  Rng mix(seed ^ (0xd1b54a32d192ed03ULL * static_cast<std::uint64_t>(slice + 1)));
  mix.next();
  return mix.next();
}

PixelRegion resolve(PixelRegion r, SensorSize s) {
  if (r.x1 <= 0) r.x1 = s.width;
  if (r.y1 <= 0) r.y1 = s.height;
  r.x0 = std::max(r.x0, 0);
  r.y0 = std::max(r.y0, 0);
  r.x1 = std::min(r.x1, s.width);
  r.y1 = std::min(r.y1, s.height);
  return r;
}

std::uint16_t margin_in(const PixelRegion& r, int x, int y) {
  const int m = std::min(std::min(x - r.x0, r.x1 - 1 - x), std::min(y - r.y0, r.y1 - 1 - y));
  return static_cast<std::uint16_t>(std::max(m, 0));
}

double deg_s_to_rad_us(double deg_s) { return deg_s * kPi / 180.0 * 1e-6; }

// Angle of a rotating bar as a function of time, and its inverse.
struct BarMotion {
  double phi0, omega0, alpha, ramp_us, phi_ramp, omega1;  // rad, rad/us, rad/us^2, us
  explicit BarMotion(const RotatingBarSpec& b)
      : phi0(b.start_angle_deg * kPi / 180.0),
        omega0(deg_s_to_rad_us(b.omega_start_deg_s)),
        alpha(b.ramp_us > 0 ? (deg_s_to_rad_us(b.omega_end_deg_s) - omega0) / b.ramp_us : 0.0),
        ramp_us(std::max(b.ramp_us, 0.0)),
        phi_ramp(phi0 + omega0 * ramp_us + 0.5 * alpha * ramp_us * ramp_us),
        omega1(deg_s_to_rad_us(b.omega_end_deg_s)) {}
  double angle(double t) const {
    if (t <= ramp_us) return phi0 + omega0 * t + 0.5 * alpha * t * t;
    return phi_ramp + omega1 * (t - ramp_us);
  }
  double omega(double t) const { return t <= ramp_us ? omega0 + alpha * t : omega1; }
  double time_of(double phi) const {
    if (phi <= phi_ramp) {  // root of 0.5 a t^2 + w0 t - d = 0, stable form
      const double d = phi - phi0;
      return 2.0 * d / (omega0 + std::sqrt(std::max(omega0 * omega0 + 2.0 * alpha * d, 0.0)));
    }
    return ramp_us + (phi - phi_ramp) / omega1;
  }
};

struct SliceContext {
  const SceneSpec& spec;
  double t_begin_us;
  double t_end_us;
  Rng& rng;
};

template <typename Emit>
void grating_slice(const GratingSpec& g, std::int16_t feature, const SliceContext& c, Emit&& emit) {
  const double a = std::max(c.t_begin_us, static_cast<double>(g.t_begin_us));
  const double b = std::min(c.t_end_us, static_cast<double>(g.t_end_us));
  if (!(a < b)) return;
  const PixelRegion r = resolve(g.region, c.spec.sensor);
  const double th = g.direction_deg * kPi / 180.0;
  const double nx = std::cos(th), ny = std::sin(th);
  const double tau = g.lifetime_us, period = g.period_px;
  for (int y = r.y0; y < r.y1; ++y) {
    for (int x = r.x0; x < r.x1; ++x) {
      const double s = x * nx + y * ny;  // pixel centre along the normal
      // Leading edge k is at phase + t/tau + k*period; trailing edge bar_width behind.
      for (int edge = 0; edge < 2; ++edge) {
        const double offset = s - g.phase_px + (edge == 0 ? 0.0 : g.bar_width_px);
        const auto k_lo = static_cast<long long>(std::floor((offset - b / tau) / period));
        const auto k_hi = static_cast<long long>(std::ceil((offset - a / tau) / period));
        for (long long k = k_lo; k <= k_hi; ++k) {
          const double t = (offset - static_cast<double>(k) * period) * tau;
          if (t < a || t >= b) continue;
          EventTruth truth;
          truth.t_true_us = t;
          truth.lifetime_us = tau;
          truth.travel_px = (t - static_cast<double>(g.t_begin_us)) / tau;
          truth.nx = nx;
          truth.ny = ny;
          truth.feature = feature;
          truth.margin_px = margin_in(r, x, y);
          emit(x, y, edge == 0 ? 1 : -1, truth, k);
        }
      }
    }
  }
}

template <typename Emit>
void bar_slice(const RotatingBarSpec& bar, std::int16_t feature, const SliceContext& c,
               Emit&& emit) {
  const BarMotion m(bar);
  const double phi_a = m.angle(c.t_begin_us), phi_b = m.angle(c.t_end_us);
  const PixelRegion r = resolve(bar.region, c.spec.sensor);
  const double half_w = 0.5 * bar.bar_width_px;
  for (int y = r.y0; y < r.y1; ++y) {
    for (int x = r.x0; x < r.x1; ++x) {
      const double dx = x - bar.centre_x, dy = y - bar.centre_y;
      const double radius = std::hypot(dx, dy);
      if (radius <= half_w + 1e-9) continue;  // always under the bar: never changes
      const double theta = std::atan2(dy, dx);
      const double delta = std::asin(half_w / radius);
      const double arm_px = radius * std::cos(delta);  // distance along the bar axis
      // The bar covers the pixel while its axis angle is within theta +- delta
      // (mod pi, two arms): it arrives at theta - delta (ON), leaves at theta + delta (OFF).
      for (int edge = 0; edge < 2; ++edge) {
        const double axis = edge == 0 ? theta - delta : theta + delta;
        const auto k_lo = static_cast<long long>(std::ceil((phi_a - axis) / kPi));
        for (long long k = k_lo;; ++k) {
          const double phi = axis + static_cast<double>(k) * kPi;
          if (phi >= phi_b) break;
          if (phi < phi_a) continue;
          // Slice membership is decided on the angle, so no crossing is lost or
          // doubled by rounding at slice ends.
          const double t = m.time_of(phi);
          EventTruth truth;
          truth.t_true_us = t;
          truth.lifetime_us = 1.0 / (m.omega(t) * arm_px);
          truth.travel_px = (phi - m.phi0) * arm_px;
          // Normal of the edge = perpendicular of the arm through the pixel, turned
          // the way the bar turns.
          truth.nx = -std::sin(axis);
          truth.ny = std::cos(axis);
          truth.feature = feature;
          truth.margin_px = margin_in(r, x, y);
          truth.scorable = radius >= bar.min_scored_radius_px;
          emit(x, y, edge == 0 ? 1 : -1, truth, k);
        }
      }
    }
  }
}

// Hot pixels: each fires hot_pixel_rate_hz on its own, uniform in time, random polarity.
template <typename Push>
void hot_pixel_slice(const SceneSpec& spec, const std::vector<std::uint32_t>& hot_pixels, Rng& rng,
                     std::int64_t a, std::int64_t b, Push&& push) {
  const double mean = spec.pixel.hot_pixel_rate_hz * static_cast<double>(b - a) * 1e-6;
  const SensorSize s = spec.sensor;
  const PixelRegion whole{0, 0, s.width, s.height};
  for (const std::uint32_t pixel : hot_pixels) {
    auto count = static_cast<std::uint64_t>(mean);
    if (rng.uniform() < mean - static_cast<double>(count)) ++count;
    const int x = static_cast<int>(pixel % static_cast<std::uint32_t>(s.width));
    const int y = static_cast<int>(pixel / static_cast<std::uint32_t>(s.width));
    for (std::uint64_t i = 0; i < count; ++i) {
      const auto t = a + static_cast<std::int64_t>(rng.below(static_cast<std::uint64_t>(b - a)));
      EventTruth truth;
      truth.t_true_us = static_cast<double>(t);
      truth.is_noise = true;
      truth.is_hot = true;
      truth.margin_px = margin_in(whole, x, y);
      push(t, x, y, rng.uniform() < 0.5 ? 1 : -1, truth);
    }
  }
}

std::string fmt_num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// "pixel.FIELD: ..." for a field out of its range (the struct's names), the
// user's parameter names for the rules across fields (`evlife synth
// --threshold-sigma`, Python's threshold_sigma=): "threshold_mismatch_sigma:
// must be in [0, threshold_log]" named neither for a --threshold below the
// default sigma.
std::string validate_pixel_model(const PixelModel& m) {
  if (!m.enabled) return {};
  const auto in = [](double v, double lo, double hi) { return v >= lo && v <= hi; };
  if (!in(m.contrast_log, 1e-3, 10.0)) return "pixel.contrast_log: must be in [0.001, 10]";
  if (!in(m.contrast_spread, 0.0, 0.99)) return "pixel.contrast_spread: must be in [0, 0.99]";
  if (!in(m.threshold_log, 0.01, 5.0)) return "pixel.threshold_log: must be in [0.01, 5]";
  if (!in(m.threshold_mismatch_sigma, 0.0, m.threshold_log)) {
    return "threshold-sigma " + fmt_num(m.threshold_mismatch_sigma) + " is more than threshold " +
           fmt_num(m.threshold_log) + ": lower threshold-sigma with it (the mismatch's sigma is at most the threshold)";
  }
  // The threshold's floor is threshold_log / 4: at most 4 * 15 < 64 events per crossing.
  if (m.contrast_log * (1.0 + m.contrast_spread) > 15.0 * m.threshold_log) {
    const std::string spread =
        m.contrast_spread > 0.0 ? " (up to +" + fmt_num(100.0 * m.contrast_spread) + " % per edge)" : "";
    return "contrast " + fmt_num(m.contrast_log) + spread + " is more than 15 thresholds of " +
           fmt_num(m.threshold_log) + ": raise threshold or lower contrast";
  }
  if (!in(m.edge_blur_px, 0.0, 10.0)) return "pixel.edge_blur_px: must be in [0, 10]";
  if (!in(m.latency_us, 0.0, 1e5)) return "pixel.latency_us: must be in [0, 1e5]";
  if (!in(m.latency_jitter_us, 0.0, 1e5)) return "pixel.latency_jitter_us: must be in [0, 1e5]";
  if (!in(m.refractory_us, 0.0, 1e5)) return "pixel.refractory_us: must be in [0, 1e5]";
  if (!in(m.hot_pixel_fraction, 0.0, 0.1)) return "pixel.hot_pixel_fraction: must be in [0, 0.1]";
  if (!in(m.hot_pixel_rate_hz, 0.0, 1e5)) return "pixel.hot_pixel_rate_hz: must be in [0, 1e5]";
  if (!in(m.cutoff_hz, 0.0, 1e6)) return "pixel.cutoff_hz: must be in [0, 1e6]";
  if (!in(m.timestamp_quantum_us, 0.0, 1e5)) return "pixel.timestamp_quantum_us: must be in [0, 1e5]";
  if (m.timestamp_quantum_us != std::floor(m.timestamp_quantum_us))  // 2.5 was half floored, half rounded
    return "timestamp-quantum-us " + fmt_num(m.timestamp_quantum_us) + ": a whole number of us (stamps are whole us)";
  return {};
}

}  // namespace

double background_events_per_s(SensorSize sensor, double noise_rate_hz_per_px, const PixelModel& pixel) {
  const double hot = pixel.enabled ? pixel.hot_pixel_fraction * pixel.hot_pixel_rate_hz : 0.0;
  return (noise_rate_hz_per_px + hot) * static_cast<double>(sensor.pixel_count());
}

std::uint64_t scene_reader_memory_bytes(const SceneSpec& spec) {
  constexpr double kBytesPerHeldEvent = 220.0;
  // A scene shorter than a slice is one slice of its duration (a 1 ms scene was refused as if 20 ms).
  const double per_slice = background_events_per_s(spec.sensor, spec.noise_rate_hz_per_px, spec.pixel) *
                           static_cast<double>(std::min(spec.slice_us, spec.duration_us)) * 1e-6;
  return static_cast<std::uint64_t>(per_slice * kBytesPerHeldEvent);
}

std::string validate_scene_spec(const SceneSpec& s) {
  if (s.sensor.width < 1 || s.sensor.height < 1 || s.sensor.width > 65535 || s.sensor.height > 65535)
    return "sensor: width and height must be in 1..65535";
  if (s.duration_us <= 0) return "duration_us: must be > 0";
  if (s.slice_us <= 0) return "slice_us: must be > 0";
  if (!(s.noise_rate_hz_per_px >= 0.0) || s.noise_rate_hz_per_px > 1e5)
    return "noise_rate_hz_per_px: must be in [0, 1e5]";
  if (!(s.jitter_sigma_us >= 0.0) || s.jitter_sigma_us > 1e5)
    return "jitter_sigma_us: must be in [0, 1e5]";
  if (s.gratings.size() + s.bars.size() > 30000) return "too many features (max 30000)";
  if (auto err = validate_pixel_model(s.pixel); !err.empty()) return err;
  for (std::size_t i = 0; i < s.gratings.size(); ++i) {
    const auto& g = s.gratings[i];
    const std::string where = "gratings[" + std::to_string(i) + "].";
    if (!(g.lifetime_us > 0.0) || !std::isfinite(g.lifetime_us)) return where + "lifetime_us: must be > 0";
    if (!(g.period_px > 0.0)) return where + "period_px: must be > 0";
    if (!(g.bar_width_px > 0.0) || g.bar_width_px >= g.period_px)
      return where + "bar_width_px: must be in (0, period_px)";
    if (!std::isfinite(g.direction_deg) || !std::isfinite(g.phase_px))
      return where + "direction_deg/phase_px: must be finite";
  }
  for (std::size_t i = 0; i < s.bars.size(); ++i) {
    const auto& b = s.bars[i];
    const std::string where = "bars[" + std::to_string(i) + "].";
    if (!(b.omega_start_deg_s > 0.0) || !(b.omega_end_deg_s > 0.0))
      return where + "omega_start_deg_s/omega_end_deg_s: must be > 0";
    if (!(b.bar_width_px > 0.0)) return where + "bar_width_px: must be > 0";
    if (!(b.ramp_us >= 0.0)) return where + "ramp_us: must be >= 0";
    if (!std::isfinite(b.centre_x) || !std::isfinite(b.centre_y) || !std::isfinite(b.start_angle_deg))
      return where + "centre/start_angle_deg: must be finite";
  }
  return {};
}

std::vector<std::string> scene_feature_names(const SceneSpec& spec) {
  std::vector<std::string> names;
  for (const auto& g : spec.gratings) {
    names.push_back("grating dir " + fmt_num(g.direction_deg) + " deg, lifetime " +
                    fmt_num(g.lifetime_us) + " us");
  }
  for (const auto& b : spec.bars) {
    names.push_back("rotating bar " + fmt_num(b.omega_start_deg_s) + "->" +
                    fmt_num(b.omega_end_deg_s) + " deg/s");
  }
  return names;
}

SyntheticSceneReader::SyntheticSceneReader(SceneSpec spec) : spec_(std::move(spec)) {
  if (auto err = validate_scene_spec(spec_); !err.empty()) {
    throw std::invalid_argument("synthetic scene: " + err);
  }
  slice_count_ = (spec_.duration_us + spec_.slice_us - 1) / spec_.slice_us;
  if (spec_.pixel.enabled) {
    // (Flooring to the timestamp quantum stamps an event up to a quantum earlier.)
    early_us_ = static_cast<std::int64_t>(
        std::ceil(detail::max_early_offset_us(spec_) + spec_.pixel.timestamp_quantum_us));
    hot_pixels_ = detail::PixelSampler(spec_.pixel, spec_.seed).hot_pixels(spec_.sensor);
  } else {
    early_us_ = static_cast<std::int64_t>(std::ceil(kJitterTruncationSigmas * spec_.jitter_sigma_us));
  }
}

void SyntheticSceneReader::generate_next_slice() {
  const std::int64_t slice = next_slice_++;
  const std::int64_t a = slice * spec_.slice_us;
  const std::int64_t b = std::min(a + spec_.slice_us, spec_.duration_us);
  Rng rng(slice_seed(spec_.seed, slice));
  const double sigma = spec_.jitter_sigma_us;
  const double max_jitter = kJitterTruncationSigmas * sigma;

  slice_.clear();
  auto push = [&](std::int64_t t_us, int x, int y, int p, const EventTruth& truth) {
    // The scene is [0, duration): a crossing's latency or jitter that stamps
    // it outside is not recorded (as the textured scene; clamped to 0 they
    // piled up at t = 0, and a slow photoreceptor fired seconds past the end).
    if (t_us < 0 || t_us >= spec_.duration_us) return;
    Pending e;
    e.event.t_us = t_us;
    e.event.x = static_cast<std::uint16_t>(x);
    e.event.y = static_cast<std::uint16_t>(y);
    e.event.p = static_cast<std::int8_t>(p);
    e.truth = truth;
    e.sequence = sequence_++;
    slice_.push_back(e);
  };
  auto emit_ideal = [&](int x, int y, int p, const EventTruth& truth, long long /*crossing*/) {
    double jitter = sigma > 0.0 ? sigma * rng.gaussian() : 0.0;
    jitter = std::clamp(jitter, -max_jitter, max_jitter);
    push(std::llround(truth.t_true_us + jitter), x, y, p, truth);
  };
  const detail::PixelSampler sampler(spec_.pixel, spec_.seed);
  // The readout's timestamp resolution (pixel model) for events stamped at a whole us.
  const auto quantized = [&](std::int64_t t_us) {
    return spec_.pixel.enabled ? static_cast<std::int64_t>(sampler.stamp_us(static_cast<double>(t_us))) : t_us;
  };
  detail::Burst burst;
  auto emit_burst = [&](int x, int y, int p, const EventTruth& truth, long long crossing) {
    detail::Crossing c{truth.t_true_us, truth.lifetime_us, x, y, p, truth.feature, crossing};
    if (static_cast<std::size_t>(truth.feature) < spec_.gratings.size()) {  // moves within [t_begin, t_end)
      const GratingSpec& g = spec_.gratings[static_cast<std::size_t>(truth.feature)];
      c.t_from_us = std::max(0.0, static_cast<double>(g.t_begin_us));
      c.t_to_us = static_cast<double>(g.t_end_us);
    }
    sampler.burst(c, burst);
    EventTruth t = truth;
    for (std::size_t i = 0; i < burst.count; ++i) {
      t.burst_index = static_cast<std::uint8_t>(i);
      push(std::llround(burst.t_us[i]), x, y, p, t);
    }
  };
  const SliceContext ctx{spec_, static_cast<double>(a), static_cast<double>(b), rng};
  std::int16_t feature = 0;
  if (spec_.pixel.enabled) {
    for (const auto& g : spec_.gratings) grating_slice(g, feature++, ctx, emit_burst);
    for (const auto& bar : spec_.bars) bar_slice(bar, feature++, ctx, emit_burst);
  } else {
    for (const auto& g : spec_.gratings) grating_slice(g, feature++, ctx, emit_ideal);
    for (const auto& bar : spec_.bars) bar_slice(bar, feature++, ctx, emit_ideal);
  }

  // Background noise: per slice, the mean count rounded at random (right
  // rates, not a Poisson process within a slice: README, "Not modelled").
  const double mean = spec_.noise_rate_hz_per_px * static_cast<double>(spec_.sensor.pixel_count()) *
                      static_cast<double>(b - a) * 1e-6;
  auto count = static_cast<std::uint64_t>(mean);
  if (rng.uniform() < mean - static_cast<double>(count)) ++count;
  const SensorSize s = spec_.sensor;
  const PixelRegion whole{0, 0, s.width, s.height};
  for (std::uint64_t i = 0; i < count; ++i) {
    const int x = static_cast<int>(rng.below(static_cast<std::uint64_t>(s.width)));
    const int y = static_cast<int>(rng.below(static_cast<std::uint64_t>(s.height)));
    const auto t = quantized(a + static_cast<std::int64_t>(rng.below(static_cast<std::uint64_t>(b - a))));
    Pending e;
    e.event = Event{t, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y),
                    static_cast<std::int8_t>(rng.uniform() < 0.5 ? 1 : -1)};
    e.truth.t_true_us = static_cast<double>(t);
    e.truth.is_noise = true;
    e.truth.margin_px = margin_in(whole, x, y);
    e.sequence = sequence_++;
    slice_.push_back(e);
  }
  hot_pixel_slice(spec_, hot_pixels_, rng, a, b, [&](std::int64_t t_us, int x, int y, int p, const EventTruth& truth) {
    push(quantized(t_us), x, y, p, truth);
  });

  const auto before = [](const Pending& l, const Pending& r) {
    return l.event.t_us != r.event.t_us ? l.event.t_us < r.event.t_us : l.sequence < r.sequence;
  };
  std::sort(slice_.begin(), slice_.end(), before);
  const auto old_size = static_cast<std::ptrdiff_t>(pending_.size());
  pending_.insert(pending_.end(), slice_.begin(), slice_.end());
  std::inplace_merge(pending_.begin(), pending_.begin() + old_size, pending_.end(), before);

  // Later slices hold crossings at b or after; their events are stamped at
  // most early_us_ before (ideal: the jitter; pixel model: half an edge ramp),
  // +0.5 from rounding, so every event earlier than that bound is final.
  if (next_slice_ >= slice_count_) {
    ready_ = pending_.size();
  } else {
    const auto bound = b - early_us_ - 1;
    ready_ = static_cast<std::size_t>(
        std::lower_bound(pending_.begin(), pending_.end(), bound,
                         [](const Pending& e, std::int64_t t) { return e.event.t_us < t; }) -
        pending_.begin());
  }
}

std::size_t SyntheticSceneReader::read_with_truth(std::span<Event> out, std::span<EventTruth> truth) {
  if (!truth.empty() && truth.size() < out.size()) out = out.first(truth.size());
  std::size_t n = 0;
  while (n < out.size()) {
    if (emitted_ == ready_) {
      if (next_slice_ >= slice_count_) break;
      pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(emitted_));
      ready_ -= emitted_;
      emitted_ = 0;
      generate_next_slice();
      continue;
    }
    const std::size_t take = std::min(out.size() - n, ready_ - emitted_);
    for (std::size_t i = 0; i < take; ++i) {
      out[n + i] = pending_[emitted_ + i].event;
      if (!truth.empty()) truth[n + i] = pending_[emitted_ + i].truth;
    }
    emitted_ += take;
    n += take;
  }
  return n;
}

std::size_t SyntheticSceneReader::read(std::span<Event> out) { return read_with_truth(out, {}); }

SyntheticScene generate_scene(const SceneSpec& spec, const GenerationStop& stop) {
  SyntheticSceneReader reader(spec);
  SyntheticScene scene;
  scene.spec = spec;
  scene.feature_names = scene_feature_names(spec);
  std::vector<Event> events(1 << 16);
  std::vector<EventTruth> truth(events.size());
  while (const std::size_t n = reader.read_with_truth(events, truth)) {
    scene.events.insert(scene.events.end(), events.begin(), events.begin() + static_cast<std::ptrdiff_t>(n));
    scene.truth.insert(scene.truth.end(), truth.begin(), truth.begin() + static_cast<std::ptrdiff_t>(n));
    if (stop && stop()) {
      scene.complete = false;
      scene.generated_events = scene.events.size();
      break;
    }
  }
  return scene;
}

}  // namespace evlife::io
