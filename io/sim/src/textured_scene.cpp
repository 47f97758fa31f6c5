// The textured scene (textured_scene.h): a dead-leaves texture per tile,
// translating, sampled by DVS pixels.
#include "evlife/io/textured_scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "dvs_pixel_model.h"
#include "hash_draws.h"

namespace evlife::io {
namespace {

using detail::combine;
using detail::gaussian;
using detail::uniform;

// What a draw is for (textured scene only; disjoint from the pixel model's
// tags by the kTextured prefix).
constexpr std::uint64_t kTextured = 0x7e47;
enum TextureDrawTag : std::uint64_t { kLeaf = 1, kReference, kLatency, kNoise, kHot };

constexpr int kSupersample = 4;            // texels per pixel
constexpr double kStepPx = 0.05;           // the texture's move per simulation step
constexpr double kMaxScorableTurnDeg = 30.0;
constexpr double kMaxScorableLifetimeRatio = 3.0;
constexpr double kGoldenAngleDeg = 137.50776405003785;
constexpr int kMaxLeaves = 200'000;

// A tile: its region on the sensor and its motion.
struct Tile {
  int x0, y0, x1, y1;
  double dir_x, dir_y;     // unit direction of motion
  double lifetime_us;      // per px along the motion
  double t_begin_us, t_end_us;
  double travel_px() const { return (t_end_us - t_begin_us) / lifetime_us; }
  // How far the texture has moved at t (px).
  double moved_px(double t_us) const { return (std::clamp(t_us, t_begin_us, t_end_us) - t_begin_us) / lifetime_us; }
};

// The blurred dead-leaves texture of a tile, in texture coordinates: a pixel
// (x, y) sees at time t the texture at (x, y) - moved_px(t) * dir.
class Texture {
 public:
  Texture(const TexturedSceneSpec& spec, const Tile& tile, int tile_index)
      : u0_(tile.x0 - tile.travel_px() - kBorderPx),
        v0_(tile.y0 - tile.travel_px() - kBorderPx) {
    const double span_x = (tile.x1 - tile.x0) + 2.0 * (tile.travel_px() + kBorderPx);
    const double span_y = (tile.y1 - tile.y0) + 2.0 * (tile.travel_px() + kBorderPx);
    w_ = static_cast<int>(std::ceil(span_x * kSupersample)) + 1;
    h_ = static_cast<int>(std::ceil(span_y * kSupersample)) + 1;
    texels_.assign(static_cast<std::size_t>(w_) * static_cast<std::size_t>(h_), 0.0);
    paint_leaves(spec, tile_index);
    blur(0.3125 * spec.pixel.edge_blur_px * kSupersample);
  }

  /// Log intensity at texture point (u, v) (px), bilinear.
  double at(double u, double v) const {
    const double fx = std::clamp((u - u0_) * kSupersample, 0.0, static_cast<double>(w_ - 2));
    const double fy = std::clamp((v - v0_) * kSupersample, 0.0, static_cast<double>(h_ - 2));
    const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
    const double ax = fx - ix, ay = fy - iy;
    const double* r0 = &texels_[static_cast<std::size_t>(iy) * static_cast<std::size_t>(w_) + static_cast<std::size_t>(ix)];
    const double* r1 = r0 + w_;
    return (1.0 - ay) * ((1.0 - ax) * r0[0] + ax * r0[1]) + ay * ((1.0 - ax) * r1[0] + ax * r1[1]);
  }

  /// Gradient (ln units per px) at (u, v): central differences a quarter pixel apart.
  void gradient(double u, double v, double& gx, double& gy) const {
    constexpr double h = 0.25;
    gx = (at(u + h, v) - at(u - h, v)) / (2.0 * h);
    gy = (at(u, v + h) - at(u, v - h)) / (2.0 * h);
  }

 private:
  static constexpr double kBorderPx = 8.0;  // around the region any pixel samples

  // Leaves front to back: each paints the texels no nearer leaf covers.
  void paint_leaves(const TexturedSceneSpec& spec, int tile_index) {
    std::vector<unsigned char> covered(texels_.size(), 0);
    std::size_t left = texels_.size();
    const double a = spec.leaf_radius_min_px, b = spec.leaf_radius_max_px;
    const double ia2 = 1.0 / (a * a), ib2 = 1.0 / (b * b);
    const double span_x = w_ / static_cast<double>(kSupersample), span_y = h_ / static_cast<double>(kSupersample);
    for (int leaf = 0; leaf < kMaxLeaves && left > 0; ++leaf) {
      const std::uint64_t key = combine(spec.seed, kTextured, kLeaf, tile_index, leaf);
      // Density ~ r^-3 on [a, b]: the inverse of its distribution function.
      const double r = 1.0 / std::sqrt(ia2 - uniform(combine(key, 0)) * (ia2 - ib2));
      const double cx = -b + uniform(combine(key, 1)) * (span_x + 2.0 * b);
      const double cy = -b + uniform(combine(key, 2)) * (span_y + 2.0 * b);
      const double level = spec.texture_contrast_log * uniform(combine(key, 3));
      const int x_lo = std::max(0, static_cast<int>(std::floor((cx - r) * kSupersample)));
      const int x_hi = std::min(w_ - 1, static_cast<int>(std::ceil((cx + r) * kSupersample)));
      const int y_lo = std::max(0, static_cast<int>(std::floor((cy - r) * kSupersample)));
      const int y_hi = std::min(h_ - 1, static_cast<int>(std::ceil((cy + r) * kSupersample)));
      const double r2 = r * r * kSupersample * kSupersample;
      for (int y = y_lo; y <= y_hi; ++y) {
        const double dy = y - cy * kSupersample;
        for (int x = x_lo; x <= x_hi; ++x) {
          const double dx = x - cx * kSupersample;
          const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(w_) + static_cast<std::size_t>(x);
          if (covered[i] || dx * dx + dy * dy > r2) continue;
          covered[i] = 1;
          texels_[i] = level;
          --left;
        }
      }
    }
    // Texels no leaf reached (rare): mid grey.
    for (std::size_t i = 0; i < texels_.size(); ++i) {
      if (!covered[i]) texels_[i] = 0.5 * spec.texture_contrast_log;
    }
  }

  // Separable Gaussian of sigma (texels), clamped at the borders.
  void blur(double sigma) {
    if (!(sigma > 0.0)) return;
    const int radius = static_cast<int>(std::ceil(3.0 * sigma));
    const std::size_t taps = 2 * static_cast<std::size_t>(radius) + 1;  // offsets -radius .. radius
    std::vector<double> k(taps);
    double sum = 0.0;
    for (std::size_t j = 0; j < taps; ++j) {
      const double d = static_cast<double>(j) - radius;
      k[j] = std::exp(-0.5 * d * d / (sigma * sigma));
      sum += k[j];
    }
    for (double& v : k) v /= sum;
    std::vector<double> tmp(texels_.size());
    const auto idx = [&](int x, int y) {
      return static_cast<std::size_t>(y) * static_cast<std::size_t>(w_) + static_cast<std::size_t>(x);
    };
    const auto offset = [&](std::size_t j) { return static_cast<int>(j) - radius; };
    for (int y = 0; y < h_; ++y) {
      for (int x = 0; x < w_; ++x) {
        double s = 0.0;
        for (std::size_t j = 0; j < taps; ++j) s += k[j] * texels_[idx(std::clamp(x + offset(j), 0, w_ - 1), y)];
        tmp[idx(x, y)] = s;
      }
    }
    for (int y = 0; y < h_; ++y) {
      for (int x = 0; x < w_; ++x) {
        double s = 0.0;
        for (std::size_t j = 0; j < taps; ++j) s += k[j] * tmp[idx(x, std::clamp(y + offset(j), 0, h_ - 1))];
        texels_[idx(x, y)] = s;
      }
    }
  }

  double u0_, v0_;
  int w_ = 0, h_ = 0;
  std::vector<double> texels_;
};

std::vector<Tile> make_tiles(const TexturedSceneSpec& spec) {
  std::vector<Tile> tiles;
  const int nx = std::max(1, spec.sensor.width / spec.tile_px);
  const int ny = std::max(1, spec.sensor.height / spec.tile_px);
  const int n = nx * ny;
  int step = 5;
  while (std::gcd(step, n) != 1) ++step;
  const auto duration = static_cast<double>(spec.duration_us);
  for (int k = 0; k < n; ++k) {
    Tile t{};
    const int tx = k % nx, ty = k / nx;
    t.x0 = tx * spec.sensor.width / nx;
    t.x1 = (tx + 1) * spec.sensor.width / nx;
    t.y0 = ty * spec.sensor.height / ny;
    t.y1 = (ty + 1) * spec.sensor.height / ny;
    const double dir = (23.0 + kGoldenAngleDeg * k) * std::numbers::pi / 180.0;
    t.dir_x = std::cos(dir);
    t.dir_y = std::sin(dir);
    // Lifetimes log-spaced, dealt to the tiles in a scrambled order (every
    // step-th, step coprime with n: each rank once) so that neighbouring
    // tiles differ.
    const int rank = n > 1 ? (k * step) % n : 0;
    const double f = n > 1 ? rank / static_cast<double>(n - 1) : 0.0;
    t.lifetime_us = spec.lifetime_min_us * std::pow(spec.lifetime_max_us / spec.lifetime_min_us, f);
    t.t_end_us = duration;
    t.t_begin_us = std::max(0.0, duration - spec.travel_px * t.lifetime_us);
    tiles.push_back(t);
  }
  return tiles;
}

struct Stamped {
  double t_us;
  Event event;
  EventTruth truth;
};

// Is the iso-line through (u, v) a straight edge over the window? Its
// normal, 1 and 2 px along it on either side, turns by at most
// kMaxScorableTurnDeg (across the edge the gradient fades into the leaves'
// flat insides: no direction there).
bool straight_edge(const Texture& tex, double u, double v, double gx, double gy) {
  const double g = std::hypot(gx, gy);
  const double cos_limit = std::cos(kMaxScorableTurnDeg * std::numbers::pi / 180.0);
  const double tx = -gy / g, ty = gx / g;  // along the iso-line
  for (const double along_px : {-2.0, -1.0, 1.0, 2.0}) {
    double hx = 0.0, hy = 0.0;
    tex.gradient(u + along_px * tx, v + along_px * ty, hx, hy);
    const double h = std::hypot(hx, hy);
    if (!(h > 0.0) || (gx * hx + gy * hy) / (g * h) < cos_limit) return false;
  }
  return true;
}

// One pixel of one tile through its motion: its events with their truth.
void simulate_pixel(const TexturedSceneSpec& spec, const detail::PixelSampler& sampler, const Texture& tex,
                    const Tile& tile, int tile_index, int x, int y, std::vector<Stamped>& out) {
  const PixelModel& m = spec.pixel;
  const double theta_on = sampler.threshold(x, y, 1), theta_off = sampler.threshold(x, y, -1);
  const double travel = tile.travel_px();
  const int steps = std::max(1, static_cast<int>(std::ceil(travel / kStepPx)));
  // After the motion the photoreceptor still settles: a few time constants more.
  const double slowest_us = m.cutoff_hz > 0.0 ? std::exp(spec.texture_contrast_log) * 1e6 / (2.0 * std::numbers::pi * m.cutoff_hz) : 0.0;
  const double t_last = std::min(static_cast<double>(spec.duration_us), tile.t_end_us + 5.0 * slowest_us);
  const double dt = (tile.t_end_us - tile.t_begin_us) / steps;
  const auto level_at = [&](double t) {
    const double d = tile.moved_px(t);
    return tex.at(x - d * tile.dir_x, y - d * tile.dir_y);
  };
  const std::uint64_t pixel_key = combine(spec.seed, kTextured, tile_index, x, y);
  double seen = level_at(tile.t_begin_us);  // the photoreceptor's output, settled on the still scene
  // Adapted to the still scene: the reference anywhere in the dead band.
  double reference = seen - theta_on + (theta_on + theta_off) * uniform(combine(pixel_key, kReference));
  double ready_us = -1.0;       // end of the refractory period
  bool reset_pending = false;   // the reference is set to the level at ready_us
  int fired = 0;
  double last_t[2] = {-1e300, -1e300}, last_lifetime[2] = {0.0, 0.0};
  int burst[2] = {0, 0};
  double t_a = tile.t_begin_us, y_a = seen;
  for (int k = 1; t_a < t_last; ++k) {
    const double t_b = std::min(t_last, tile.t_begin_us + k * dt);
    const double input = level_at(t_b);
    double y_b = input;
    if (m.cutoff_hz > 0.0) {  // first order, time constant set by the intensity seen
      const double tau_us = std::exp(spec.texture_contrast_log - y_a) * 1e6 / (2.0 * std::numbers::pi * m.cutoff_hz);
      y_b = input + (y_a - input) * std::exp(-(t_b - t_a) / tau_us);
    }
    const auto seen_at = [&](double t) { return t_b > t_a ? y_a + (y_b - y_a) * (t - t_a) / (t_b - t_a) : y_b; };
    for (;;) {
      if (ready_us > t_b) break;
      const double t0 = std::max(t_a, ready_us);
      if (reset_pending) {
        reference = seen_at(t0);
        reset_pending = false;
      }
      const double y0 = seen_at(t0);
      int p = 0;
      double t_fire = 0.0;
      if (y0 >= reference + theta_on) {
        p = 1, t_fire = t0;
      } else if (y0 <= reference - theta_off) {
        p = -1, t_fire = t0;
      } else if (y_b >= reference + theta_on) {
        p = 1, t_fire = t0 + (reference + theta_on - y0) / (y_b - y0) * (t_b - t0);
      } else if (y_b <= reference - theta_off) {
        p = -1, t_fire = t0 + (reference - theta_off - y0) / (y_b - y0) * (t_b - t0);
      } else {
        break;
      }
      const double latency = sampler.latency_us(combine(pixel_key, kLatency, fired++));
      const double t_stamp = sampler.stamp_us(t_fire + latency);
      ready_us = t_fire + latency + m.refractory_us;  // reset at the stamp, held for the refractory period
      reset_pending = true;
      if (!(t_stamp < static_cast<double>(spec.duration_us))) continue;
      // Truth where the pixel sat in the texture at the crossing.
      const double d = tile.moved_px(t_fire);
      const double u = x - d * tile.dir_x, v = y - d * tile.dir_y;
      double gx = 0.0, gy = 0.0;
      tex.gradient(u, v, gx, gy);
      const double g = std::hypot(gx, gy);
      const double along = (gx * tile.dir_x + gy * tile.dir_y) / g;  // cos(normal, motion)
      EventTruth truth;
      truth.t_true_us = t_fire;
      truth.feature = static_cast<std::int16_t>(tile_index);
      truth.margin_px = static_cast<std::uint16_t>(std::min({x - tile.x0, tile.x1 - 1 - x, y - tile.y0, tile.y1 - 1 - y}));
      truth.travel_px = d;
      const bool moving = g > 0.0 && std::fabs(along) > 0.0 && t_fire > tile.t_begin_us && t_fire < tile.t_end_us;
      if (moving) {
        truth.lifetime_us = tile.lifetime_us / std::fabs(along);
        const double s = along > 0.0 ? 1.0 : -1.0;  // the iso-line moves along +normal where g . v > 0
        truth.nx = s * gx / g;
        truth.ny = s * gy / g;
        // Weak gradients: a theta needs over 4 px of it, no edge there.
        truth.scorable = std::fabs(along) * kMaxScorableLifetimeRatio >= 1.0 && g * 4.0 >= m.threshold_log &&
                         straight_edge(tex, u, v, gx, gy);
      } else {
        // Fired while the scene was still (the photoreceptor settling):
        // real events whose lifetime no edge defines.
        truth.scorable = false;
        truth.lifetime_us = tile.lifetime_us;
      }
      const int pi = p > 0 ? 1 : 0;
      burst[pi] = t_fire - last_t[pi] < 2.0 * std::max(last_lifetime[pi], truth.lifetime_us) ? std::min(burst[pi] + 1, 255) : 0;
      last_t[pi] = t_fire;
      last_lifetime[pi] = truth.lifetime_us;
      truth.burst_index = static_cast<std::uint8_t>(burst[pi]);
      out.push_back({t_stamp, Event{static_cast<std::int64_t>(std::floor(t_stamp)), static_cast<std::uint16_t>(x),
                                    static_cast<std::uint16_t>(y), static_cast<std::int8_t>(p)},
                     truth});
    }
    t_a = t_b;
    y_a = y_b;
  }
}

// Background activity (uniform per pixel) and hot pixels: Poisson processes
// of random polarity, noise in the truth.
void add_noise(const TexturedSceneSpec& spec, const detail::PixelSampler& sampler, std::vector<Stamped>& out) {
  const auto duration = static_cast<double>(spec.duration_us);
  const auto fire = [&](int x, int y, double rate_hz, std::uint64_t key, bool hot) {
    if (!(rate_hz > 0.0)) return;
    const double mean_gap_us = 1e6 / rate_hz;
    double t = 0.0;
    for (std::uint64_t i = 0;; ++i) {
      t += -mean_gap_us * std::log(1.0 - uniform(combine(key, i, 0)));
      if (!(t < duration)) return;
      const double stamp = sampler.stamp_us(t);
      EventTruth truth;
      truth.t_true_us = t;
      truth.is_noise = true;
      truth.is_hot = hot;
      truth.scorable = false;
      truth.margin_px = static_cast<std::uint16_t>(std::min({x, spec.sensor.width - 1 - x, y, spec.sensor.height - 1 - y}));
      const std::int8_t p = uniform(combine(key, i, 1)) < 0.5 ? -1 : 1;
      out.push_back({stamp, Event{static_cast<std::int64_t>(std::floor(stamp)), static_cast<std::uint16_t>(x),
                                  static_cast<std::uint16_t>(y), p},
                     truth});
    }
  };
  for (int y = 0; y < spec.sensor.height; ++y) {
    for (int x = 0; x < spec.sensor.width; ++x) {
      fire(x, y, spec.noise_rate_hz_per_px, combine(spec.seed, kTextured, kNoise, x, y), false);
    }
  }
  for (const std::uint32_t pixel : sampler.hot_pixels(spec.sensor)) {
    const int x = static_cast<int>(pixel % static_cast<std::uint32_t>(spec.sensor.width));
    const int y = static_cast<int>(pixel / static_cast<std::uint32_t>(spec.sensor.width));
    fire(x, y, spec.pixel.hot_pixel_rate_hz, combine(spec.seed, kTextured, kHot, x, y), true);
  }
}

}  // namespace

std::string validate_textured_scene_spec(const TexturedSceneSpec& s) {
  SceneSpec as_scene;  // the checks the two scenes share
  as_scene.sensor = s.sensor;
  as_scene.duration_us = s.duration_us;
  as_scene.noise_rate_hz_per_px = s.noise_rate_hz_per_px;
  as_scene.pixel = s.pixel;
  if (std::string why = validate_scene_spec(as_scene); !why.empty()) return why;
  if (!s.pixel.enabled) return "pixel: the textured scene needs the pixel model enabled";
  if (s.tile_px < 16 || s.tile_px > 4096) return "tile_px: must be in [16, 4096]";
  if (!(s.travel_px >= 1.0 && s.travel_px <= 1000.0)) return "travel_px: must be in [1, 1000]";
  // A tile's texture is held at kSupersample^2 texels per px (8 bytes each).
  if (s.tile_px + 2.0 * s.travel_px > 2000.0) return "tile_px + 2 x travel_px: must be at most 2000 (texture memory)";
  if (!(s.lifetime_min_us >= 1.0 && s.lifetime_max_us >= s.lifetime_min_us && s.lifetime_max_us <= 1e7))
    return "lifetime_min_us, lifetime_max_us: need 1 <= min <= max <= 1e7";
  if (!(s.texture_contrast_log > 0.0 && s.texture_contrast_log <= 10.0)) return "texture_contrast_log: must be in (0, 10]";
  if (!(s.leaf_radius_min_px >= 0.5 && s.leaf_radius_max_px >= s.leaf_radius_min_px && s.leaf_radius_max_px <= 1000.0))
    return "leaf_radius_min_px, leaf_radius_max_px: need 0.5 <= min <= max <= 1000";
  return "";
}

TexturedSceneSpec textured_scene_like(const SceneSpec& scene) {
  TexturedSceneSpec spec;
  spec.sensor = scene.sensor;
  spec.duration_us = scene.duration_us;
  spec.seed = scene.seed;
  spec.pixel = scene.pixel;
  spec.noise_rate_hz_per_px = scene.noise_rate_hz_per_px;
  return spec;
}

std::uint64_t textured_scene_memory_bytes(const TexturedSceneSpec& spec) {
  constexpr double kBytesPerHeldEvent = 135.0;
  const double events = background_events_per_s(spec.sensor, spec.noise_rate_hz_per_px, spec.pixel) *
                        static_cast<double>(spec.duration_us) * 1e-6;
  return static_cast<std::uint64_t>(events * kBytesPerHeldEvent);
}

SyntheticScene generate_textured_scene(const TexturedSceneSpec& spec, const GenerationStop& stop) {
  if (std::string why = validate_textured_scene_spec(spec); !why.empty()) {
    throw std::invalid_argument("textured scene: " + why);
  }
  const detail::PixelSampler sampler(spec.pixel, spec.seed);
  std::vector<Stamped> stamped;
  const std::vector<Tile> tiles = make_tiles(spec);
  SyntheticScene scene;
  scene.spec.sensor = spec.sensor;
  scene.spec.duration_us = spec.duration_us;
  scene.spec.seed = spec.seed;
  scene.spec.pixel = spec.pixel;
  scene.spec.noise_rate_hz_per_px = spec.noise_rate_hz_per_px;
  for (std::size_t k = 0; k < tiles.size(); ++k) {
    const Tile& tile = tiles[k];
    const Texture tex(spec, tile, static_cast<int>(k));
    for (int y = tile.y0; y < tile.y1; ++y) {
      for (int x = tile.x0; x < tile.x1; ++x) simulate_pixel(spec, sampler, tex, tile, static_cast<int>(k), x, y, stamped);
    }
    char name[96];
    std::snprintf(name, sizeof name, "texture tile %zu, %.0f deg, lifetime %.0f us", k,
                  std::atan2(tile.dir_y, tile.dir_x) * 180.0 / std::numbers::pi, tile.lifetime_us);
    scene.feature_names.emplace_back(name);
    if (stop && stop()) {
      scene.complete = false;
      scene.generated_events = stamped.size();
      return scene;
    }
  }
  add_noise(spec, sampler, stamped);
  // Time order; ties in the order generated (stable): deterministic.
  std::stable_sort(stamped.begin(), stamped.end(), [](const Stamped& a, const Stamped& b) { return a.t_us < b.t_us; });
  scene.events.reserve(stamped.size());
  scene.truth.reserve(stamped.size());
  for (const Stamped& s : stamped) {
    scene.events.push_back(s.event);
    scene.truth.push_back(s.truth);
  }
  return scene;
}

bool apply_pixel_setting(TexturedSceneSpec& spec, std::string_view name) {
  SceneSpec as_scene;
  if (name == "ideal" || !apply_pixel_setting(as_scene, name)) return false;
  spec.pixel = as_scene.pixel;
  spec.noise_rate_hz_per_px = as_scene.noise_rate_hz_per_px;
  return true;
}

std::size_t SceneMemoryReader::read(std::span<Event> out) {
  const std::size_t n = std::min(out.size(), scene_.events.size() - next_);
  std::copy_n(scene_.events.begin() + static_cast<std::ptrdiff_t>(next_), n, out.begin());
  next_ += n;
  return n;
}

std::size_t SceneMemoryReader::read_with_truth(std::span<Event> out, std::span<EventTruth> truth) {
  const std::size_t from = next_;
  const std::size_t n = read(out.first(std::min(out.size(), truth.size())));
  std::copy_n(scene_.truth.begin() + static_cast<std::ptrdiff_t>(from), n, truth.begin());
  return n;
}

}  // namespace evlife::io
