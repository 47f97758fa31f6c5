// Named synthetic scenes: the families of the accuracy test, the bundled
// sample of `evlife synth` and the throughput bench.
#include <algorithm>
#include <array>
#include <cmath>

#include "evlife/io/synthetic_scene.h"

namespace evlife::io {
namespace {

// Log-spaced lifetimes spanning the range (300 us .. 20 ms).
constexpr std::array<double, 7> kLifetimesUs{300, 600, 1200, 2500, 5000, 10000, 20000};

// Golden-angle steps from 23 deg: directions spread over 0..360, mostly off
// the axes (an axis-aligned edge is the easy case).
double tile_direction_deg(int i) { return std::fmod(23.0 + 137.508 * i, 360.0); }

// Tiles of gratings. `pass_time_us` sets the bar period (period * lifetime);
// a pixel sees a new bar of each polarity once per period, and older passes
// stay in the time surface as stale events.
// The tiles cover columns [0, width) of the sensor.
void add_grating_tiles(SceneSpec& spec, int width, int tile_px, double pass_time_us, double min_period_px,
                       double max_period_px, int max_passes) {
  const int nx = std::max(1, static_cast<int>(std::lround(width / double(tile_px))));
  const int ny = std::max(1, static_cast<int>(std::lround(spec.sensor.height / double(tile_px))));
  for (int ty = 0; ty < ny; ++ty) {
    for (int tx = 0; tx < nx; ++tx) {
      const int i = ty * nx + tx;
      GratingSpec g;
      g.region = {tx * width / nx, ty * spec.sensor.height / ny,
                  (tx + 1) * width / nx, (ty + 1) * spec.sensor.height / ny};
      g.lifetime_us = kLifetimesUs[static_cast<std::size_t>(i) % kLifetimesUs.size()];
      g.direction_deg = tile_direction_deg(i);
      g.period_px = std::clamp(std::round(pass_time_us / g.lifetime_us), min_period_px, max_period_px);
      g.bar_width_px = std::round(g.period_px / 2.0);
      g.phase_px = 3.7 * i;
      if (max_passes > 0) {  // the last max_passes periods of the scene: after any warm-up
        const auto active_us = static_cast<std::int64_t>(max_passes * g.period_px * g.lifetime_us);
        g.t_begin_us = std::max<std::int64_t>(0, spec.duration_us - active_us);
        g.t_end_us = spec.duration_us;
      }
      spec.gratings.push_back(g);
    }
  }
}

RotatingBarSpec flip_bar(double cx, double cy, std::int64_t duration_us) {
  RotatingBarSpec b;
  b.centre_x = cx;
  b.centre_y = cy;
  b.bar_width_px = 5.0;
  b.start_angle_deg = 10.0;
  b.omega_start_deg_s = 150.0;
  b.omega_end_deg_s = 1200.0;  // the paper's quadrotor flip
  b.ramp_us = static_cast<double>(duration_us);
  b.min_scored_radius_px = 12.0;
  return b;
}

}  // namespace

SceneSpec edges_scene(SensorSize sensor, std::int64_t duration_us, std::uint64_t seed, int max_passes) {
  SceneSpec s;
  s.sensor = sensor;
  s.duration_us = duration_us;
  s.seed = seed;
  add_grating_tiles(s, sensor.width, 60, 9000.0, 10.0, 30.0, max_passes);
  return s;
}

SceneSpec rotating_bar_scene(SensorSize sensor, std::int64_t duration_us, std::uint64_t seed) {
  SceneSpec s;
  s.sensor = sensor;
  s.duration_us = duration_us;
  s.seed = seed;
  // Off the pixel grid on purpose: no symmetric degeneracies at the centre.
  s.bars.push_back(flip_bar(sensor.width / 2.0 - 0.5 + 0.37, sensor.height / 2.0 - 0.5 + 0.21,
                            duration_us));
  return s;
}

SceneSpec mixed_scene(SensorSize sensor, std::int64_t duration_us, std::uint64_t seed) {
  SceneSpec s;
  s.sensor = sensor;
  s.duration_us = duration_us;
  s.seed = seed;
  const int half_w = sensor.width / 2, half_h = sensor.height / 2;
  // Gratings move for three bar periods each (then stop), in turn, so that the
  // sample stays small (~100 k events per second on 128 x 128).
  GratingSpec slow;  // a slow, wide-spaced pattern drifting down-right
  slow.region = {0, 0, half_w, half_h};
  slow.direction_deg = 30.0;
  slow.lifetime_us = 4000.0;
  slow.period_px = 24.0;
  slow.bar_width_px = 8.0;
  slow.t_begin_us = duration_us / 10;
  slow.t_end_us = slow.t_begin_us + static_cast<std::int64_t>(3 * slow.period_px * slow.lifetime_us);
  GratingSpec fast;  // a fast one moving up-left
  fast.region = {0, half_h, half_w, sensor.height};
  fast.direction_deg = 200.0;
  fast.lifetime_us = 800.0;
  fast.period_px = 40.0;
  fast.bar_width_px = 12.0;
  fast.phase_px = 5.0;
  fast.t_begin_us = duration_us / 2;
  fast.t_end_us = fast.t_begin_us + static_cast<std::int64_t>(3 * fast.period_px * fast.lifetime_us);
  s.gratings = {slow, fast};
  RotatingBarSpec bar = flip_bar(half_w + (sensor.width - half_w) / 2.0 - 0.5 + 0.37,
                                 sensor.height / 2.0 - 0.5 + 0.21, duration_us);
  bar.region = {half_w, 0, sensor.width, sensor.height};
  s.bars.push_back(bar);
  return s;
}

SceneSpec large_scene(SensorSize sensor, std::int64_t duration_us, std::uint64_t seed) {
  SceneSpec s;
  s.sensor = sensor;
  s.duration_us = duration_us;
  s.seed = seed;
  add_grating_tiles(s, sensor.width, 80, 30000.0, 16.0, 100.0, 0);
  return s;
}

SceneSpec edges_and_bar_scene(SensorSize sensor, std::int64_t duration_us, std::uint64_t seed) {
  SceneSpec s;
  s.sensor = sensor;
  s.duration_us = duration_us;
  s.seed = seed;
  const int tiles_w = sensor.width * 2 / 3;
  add_grating_tiles(s, tiles_w, 60, 9000.0, 10.0, 30.0, 6);
  const double cx = tiles_w + (sensor.width - tiles_w) / 2.0 - 0.5 + 0.37;
  RotatingBarSpec bar = flip_bar(cx, sensor.height / 2.0 - 0.5 + 0.21, duration_us);
  bar.region = {tiles_w, 0, sensor.width, sensor.height};
  s.bars.push_back(bar);
  return s;
}

std::optional<SceneSpec> scene_preset(std::string_view name, SensorSize sensor,
                                      std::int64_t duration_us, std::uint64_t seed) {
  if (name == "edges") return edges_scene(sensor, duration_us, seed);
  if (name == "bar") return rotating_bar_scene(sensor, duration_us, seed);
  if (name == "mixed") return mixed_scene(sensor, duration_us, seed);
  if (name == "large") return large_scene(sensor, duration_us, seed);
  if (name == "edges-bar") return edges_and_bar_scene(sensor, duration_us, seed);
  return std::nullopt;
}

// Sources of the figures: PixelModel's comments (synthetic_scene.h).
PixelModel dvs_pixel_normal() {
  PixelModel m;
  m.enabled = true;
  m.latency_us = 80.0;
  m.latency_jitter_us = 40.0;
  m.refractory_us = 200.0;
  return m;
}

PixelModel dvs_pixel_dim() {
  PixelModel m = dvs_pixel_normal();
  m.latency_us = 500.0;
  m.latency_jitter_us = 300.0;
  m.refractory_us = 800.0;
  return m;
}

std::span<const PixelParameter> pixel_parameters() {
  static constexpr PixelParameter kParameters[] = {
      {"contrast", &PixelModel::contrast_log, 1e-3, 10.0},
      {"threshold", &PixelModel::threshold_log, 0.01, 5.0},
      {"threshold-sigma", &PixelModel::threshold_mismatch_sigma, 0.0, 5.0},
      {"edge-blur-px", &PixelModel::edge_blur_px, 0.0, 10.0},
      {"latency-us", &PixelModel::latency_us, 0.0, 1e5},
      {"latency-jitter-us", &PixelModel::latency_jitter_us, 0.0, 1e5},
      {"refractory-us", &PixelModel::refractory_us, 0.0, 1e5},
      {"hot-pixels", &PixelModel::hot_pixel_fraction, 0.0, 0.1},
      {"hot-rate", &PixelModel::hot_pixel_rate_hz, 0.0, 1e5},
      {"cutoff-hz", &PixelModel::cutoff_hz, 0.0, 1e6},
      {"timestamp-quantum-us", &PixelModel::timestamp_quantum_us, 0.0, 1e5},
  };
  return kParameters;
}

bool apply_pixel_setting(SceneSpec& spec, std::string_view name) {
  if (name == "ideal") return true;
  if (name == "dvs") {
    spec.pixel = dvs_pixel_normal();
    spec.noise_rate_hz_per_px = kDvsNormalNoiseRateHzPerPx;
    return true;
  }
  if (name == "dvs-dim") {
    spec.pixel = dvs_pixel_dim();
    spec.noise_rate_hz_per_px = kDvsDimNoiseRateHzPerPx;
    return true;
  }
  return false;
}

}  // namespace evlife::io
