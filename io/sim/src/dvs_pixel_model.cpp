// The DVS pixel model: bursts per edge crossing, threshold mismatch, hot
// pixels (see dvs_pixel_model.h and PixelModel in synthetic_scene.h).
#include "dvs_pixel_model.h"

#include "hash_draws.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

namespace evlife::io::detail {
namespace {

// What a draw is for: the same identity never feeds two draws.
enum PixelDrawTag : std::uint64_t { kContrast = 1, kThreshold, kResidual, kLatency, kHot };

constexpr double kLatencyTruncationSigmas = 4.0;
constexpr int kLatencyDraws = 8;  // rejection tries before falling back to the mean

}  // namespace

double PixelSampler::contrast(int feature) const {
  // Not seeded: the contrast belongs to the scene, not to the sensor's noise.
  const double u = uniform(combine(kContrast, static_cast<std::uint64_t>(feature)));
  return m_.contrast_log * (1.0 + m_.contrast_spread * (2.0 * u - 1.0));
}

double PixelSampler::threshold(int x, int y, int p) const {
  const double g = gaussian(combine(seed_, kThreshold, static_cast<std::uint64_t>(x),
                                    static_cast<std::uint64_t>(y), static_cast<std::uint64_t>(p > 0)));
  // A threshold cannot vanish; the floor is > 6 sigma away for the settings.
  return std::max(m_.threshold_log + m_.threshold_mismatch_sigma * g, 0.25 * m_.threshold_log);
}

double PixelSampler::ramp_us(double lifetime_us) const {
  return std::min(m_.edge_blur_px * lifetime_us, kMaxEdgeRampUs);
}

double PixelSampler::latency_us(std::uint64_t key) const {
  const double mu = m_.latency_us, sigma = m_.latency_jitter_us;
  if (sigma <= 0.0) return mu;
  // Gaussian truncated to [max(0, mu - 4 sigma), mu + 4 sigma] by rejection
  // (a clamp would pile events up at zero latency when sigma ~ mu).
  for (int i = 0; i < kLatencyDraws; ++i) {
    const double g = gaussian(combine(key, static_cast<std::uint64_t>(i)));
    const double l = mu + sigma * g;
    if (l >= 0.0 && std::fabs(g) <= kLatencyTruncationSigmas) return l;
  }
  return mu;
}

namespace {

// The log intensity a pixel's comparator sees during one crossing: the edge's
// ramp (from L_a at t_a linearly to L_b at t_b; steady outside), through the
// photoreceptor's first-order low-pass of time constant T > 0.
// The pixel has settled at L_a before t_a (the scene was still there).
class PixelResponse {
 public:
  PixelResponse(double t_a, double t_b, double l_a, double l_b, double time_constant_us)
      : t_a_(t_a), t_b_(t_b), l_a_(l_a), l_b_(l_b), T_(time_constant_us) {
    slope_ = t_b_ > t_a_ ? (l_b_ - l_a_) / (t_b_ - t_a_) : 0.0;
    y_b_ = t_b_ > t_a_ ? on_ramp(t_b_ - t_a_) : l_a_;
  }

  double level(double t) const {
    if (t <= t_a_) return l_a_;
    if (t <= t_b_) return on_ramp(t - t_a_);
    return l_b_ - (l_b_ - y_b_) * std::exp(-(t - t_b_) / T_);
  }
  /// The level approached as t grows (reached only in the limit).
  double final_level() const { return l_b_; }

  /// The first time the level reaches `target`, l_a < target < l_b.
  double time_of(double target) const {
    if (target > y_b_) return t_b_ - T_ * std::log((l_b_ - target) / (l_b_ - y_b_));
    // On the ramp: u - T (1 - exp(-u / T)) = m, increasing and convex in u,
    // so Newton's steps from the right end decrease monotonically to the root.
    const double m = (target - l_a_) / slope_;
    double u = t_b_ - t_a_;
    for (int i = 0; i < 60; ++i) {
      const double decay = -std::expm1(-u / T_);  // 1 - exp(-u / T)
      const double step = (u - T_ * decay - m) / decay;
      u -= step;
      if (!(step > 1e-9 * (u + T_))) break;
    }
    return t_a_ + std::max(u, 0.0);
  }

 private:
  double on_ramp(double u) const { return l_a_ + slope_ * (u + T_ * std::expm1(-u / T_)); }

  double t_a_, t_b_, l_a_, l_b_, T_;
  double slope_ = 0.0, y_b_ = 0.0;
};

}  // namespace

double PixelSampler::stamp_us(double t_us) const {
  const double q = m_.timestamp_quantum_us;
  return q > 1.0 ? std::floor(t_us / q) * q : t_us;
}

void PixelSampler::burst(const Crossing& c, Burst& out) const {
  out.count = 0;
  const double contrast_log = contrast(c.feature);
  const double theta = threshold(c.x, c.y, c.p);
  const double ramp = ramp_us(c.lifetime_us);
  const double start = c.t_c_us - 0.5 * ramp;
  const auto level_at = [&](double t) {  // log intensity accumulated by the edge at t
    t = std::clamp(t, c.t_from_us, c.t_to_us);
    if (ramp <= 0.0) return t >= c.t_c_us ? contrast_log : 0.0;
    return contrast_log * std::clamp((t - start) / ramp, 0.0, 1.0);
  };
  // With a limited photoreceptor bandwidth the comparator sees the ramp
  // low-passed; without, the ramp itself (the formulas below, unchanged).
  // The bandwidth follows the photocurrent, so it is the level the edge
  // brings that sets it: cutoff_hz on the bright side an ON edge brings, e^-C
  // of it on the dark side an OFF edge brings (v2e: the filter's rate scales
  // with the input's intensity).
  std::optional<PixelResponse> response;
  if (m_.cutoff_hz > 0.0) {
    const double ramp_from = ramp <= 0.0 ? c.t_c_us : start;
    response.emplace(std::clamp(ramp_from, c.t_from_us, c.t_to_us),
                     std::clamp(ramp_from + std::max(ramp, 0.0), c.t_from_us, c.t_to_us), level_at(c.t_from_us),
                     level_at(c.t_to_us),
                     (c.p > 0 ? 1.0 : std::exp(contrast_log)) * 1e6 / (2.0 * std::numbers::pi * m_.cutoff_hz));
  }
  const auto level = [&](double t) { return response ? response->level(t) : level_at(t); };
  const std::uint64_t key = combine(seed_, static_cast<std::uint64_t>(c.feature), static_cast<std::uint64_t>(c.x),
                                    static_cast<std::uint64_t>(c.y), static_cast<std::uint64_t>(c.p > 0),
                                    static_cast<std::uint64_t>(c.index));
  // Residual already accumulated since the pixel's last reset: the reference
  // sits r0 below the current level.
  double reference = level(c.t_from_us) - theta * uniform(combine(key, kResidual));
  while (out.count < kMaxBurstEvents) {
    // Above the level at t_from: the reference starts less than theta below it.
    const double target = reference + theta;
    double t_fire = 0.0;
    if (response) {
      if (!(target < response->final_level())) break;  // approached, never reached
      t_fire = response->time_of(target);
    } else {
      if (target > level_at(c.t_to_us)) break;
      t_fire = ramp <= 0.0 ? c.t_c_us : start + ramp * target / contrast_log;
    }
    const double t_stamp = t_fire + latency_us(combine(key, kLatency, out.count));
    out.t_us[out.count++] = stamp_us(t_stamp);
    // Reset at the timestamp, held in reset for the refractory period: the
    // new reference is the level at release.
    reference = level(t_stamp + m_.refractory_us);
  }
}

std::vector<std::uint32_t> PixelSampler::hot_pixels(SensorSize sensor) const {
  const auto n = static_cast<std::uint64_t>(sensor.pixel_count());
  if (!(m_.hot_pixel_fraction > 0.0) || n == 0) return {};
  const auto wanted = std::min<std::uint64_t>(
      n, std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::llround(m_.hot_pixel_fraction * static_cast<double>(n)))));
  std::vector<bool> taken(n, false);
  std::vector<std::uint32_t> pixels;
  for (std::uint64_t i = 0; pixels.size() < wanted; ++i) {
    const auto idx = static_cast<std::uint32_t>(mix(combine(seed_, kHot, i)) % n);
    if (taken[idx]) continue;
    taken[idx] = true;
    pixels.push_back(idx);
  }
  std::sort(pixels.begin(), pixels.end());
  return pixels;
}

double max_early_offset_us(const SceneSpec& spec) {
  if (!spec.pixel.enabled) return 0.0;
  const PixelSampler sampler(spec.pixel, spec.seed);
  double longest_ramp = 0.0;
  for (const auto& g : spec.gratings) longest_ramp = std::max(longest_ramp, sampler.ramp_us(g.lifetime_us));
  for (const auto& b : spec.bars) {
    // Lifetime 1 / (omega * arm), arm = sqrt(r^2 - (w/2)^2): largest at the
    // slowest rotation and the shortest arm among the pixels that see edges.
    PixelRegion r = b.region;
    if (r.x1 <= 0) r.x1 = spec.sensor.width;
    if (r.y1 <= 0) r.y1 = spec.sensor.height;
    const double half_w = 0.5 * b.bar_width_px;
    double min_arm = std::numeric_limits<double>::infinity();
    for (int y = std::max(r.y0, 0); y < std::min(r.y1, spec.sensor.height); ++y) {
      for (int x = std::max(r.x0, 0); x < std::min(r.x1, spec.sensor.width); ++x) {
        const double radius = std::hypot(x - b.centre_x, y - b.centre_y);
        if (radius <= half_w + 1e-9) continue;
        min_arm = std::min(min_arm, radius * std::cos(std::asin(half_w / radius)));
      }
    }
    if (!std::isfinite(min_arm)) continue;
    const double omega_min = std::min(b.omega_start_deg_s, b.omega_end_deg_s) * std::numbers::pi / 180.0 * 1e-6;
    longest_ramp = std::max(longest_ramp, sampler.ramp_us(1.0 / (omega_min * min_arm)));
  }
  return 0.5 * longest_ramp;
}

}  // namespace evlife::io::detail
