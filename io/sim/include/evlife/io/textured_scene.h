// A textured scene through the DVS pixel model: what real cameras see more
// than isolated bars. The gratings and bars of synthetic_scene.h are straight
// edges on a uniform ground; real scenes are textures of many edges of every
// contrast, orientation and curvature, with occlusions and shading. This scene
// is a "dead leaves" image (Lee, Mumford & Huang 2001: overlapping discs of
// random grey, radii ~ r^-3; it has the scale invariance and the sharp
// occlusion edges of natural images) blurred by the optics, cut into tiles
// that each translate with their own velocity, and sampled by every pixel as a
// log-intensity signal L(t). Each pixel fires like PixelModel's (threshold
// with mismatch, reset to the level at release after latency and refractory
// period, latency jitter, photoreceptor low-pass, timestamp quantum, hot
// pixels) on that signal, stepped in 0.05 px moves (ESIM and v2e do the same on
// rendered frames).
//
// Ground truth of an edge event: the texture's gradient g where the pixel sat
// in the texture at the threshold crossing; lifetime = |g| / |g . v| (the time
// the iso-line through the pixel needs to move one pixel along its normal),
// direction = the normal the iso-line moves along. Not scorable where the
// local surface is not a plane: the gradient's direction turns by more than
// kMaxScorableTurnDeg within 1.5 px (corners, occlusion junctions, curved
// texture), or the edge moves nearly along itself (lifetime over
// kMaxScorableLifetimeRatio x the tile's), or the gradient is too weak to
// be an edge.
//
// Deterministic: the same spec gives the same events bit for bit (hashes of
// the seed, no std:: distributions). Generated whole in memory (no streaming
// reader); the sensor's pixels are simulated one after the other.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <utility>

#include "evlife/io/event_reader.h"
#include "evlife/io/synthetic_scene.h"

namespace evlife::io {

struct TexturedSceneSpec {
  SensorSize sensor{240, 180};
  std::int64_t duration_us = 600'000;
  /// Side of the square tiles (px); each tile's texture translates on its own.
  int tile_px = 60;
  /// How far each tile's texture moves (px), in the scene's last
  /// travel_px x tile lifetime (all of the scene for the slow tiles).
  double travel_px = 30.0;
  /// The tiles' lifetimes (time to move 1 px along their motion), log-spaced
  /// over the tiles from the shortest to the longest.
  double lifetime_min_us = 500.0;
  double lifetime_max_us = 20'000.0;
  /// The leaves' log intensities are uniform over [0, this] (ln units): 1.0 =
  /// surfaces of up to 2.7:1 reflectance under one light.
  double texture_contrast_log = 1.0;
  /// Dead-leaves radii (px), density ~ r^-3 between these.
  double leaf_radius_min_px = 2.0;
  double leaf_radius_max_px = 40.0;
  /// Background activity (events per pixel per second), random polarity.
  double noise_rate_hz_per_px = kDvsNormalNoiseRateHzPerPx;
  std::uint64_t seed = 1;
  /// The pixels (must be enabled). contrast_log and contrast_spread are not
  /// used (the texture sets the contrasts); edge_blur_px sets the optics: a
  /// Gaussian of sigma 0.3125 x edge_blur_px, whose 10-90 % width equals
  /// that of the linear ramp over edge_blur_px the edge scenes use.
  PixelModel pixel = dvs_pixel_normal();
};

/// Returns "" when the spec is usable, else a message naming the field.
std::string validate_textured_scene_spec(const TexturedSceneSpec& spec);

/// The textured scene with the sensor, duration, seed, pixels and background
/// activity of `scene` (the fields the command line and Python parse into a
/// SceneSpec for either scene); the texture's own fields keep their defaults.
TexturedSceneSpec textured_scene_like(const SceneSpec& scene);

/// The scene: events time-ordered, truth[i] for events[i] (feature = tile
/// index, margin_px = distance to the tile's border, travel_px = distance the
/// tile has moved, burst_index = events of the same polarity at the pixel
/// since it was last quiet for 2 true lifetimes). spec.sensor of the result
/// is the sensor; its gratings and bars are empty. Throws
/// std::invalid_argument on a bad spec. `stop` is asked after each tile and
/// before the background: stopped, the scene holds no event (its events are
/// time-ordered only once all are generated).
SyntheticScene generate_textured_scene(const TexturedSceneSpec& spec, const GenerationStop& stop = {});

/// What generate_textured_scene holds (the scene whole), for a refusal
/// before it starts: the background events at ~135 B each (event, truth and
/// the sort: 4.39 GB peak for 32.8 M events, `evlife synth --scene textured
/// --sensor 128x128 --duration 20 --noise-rate 100 -o t.h5`); the texture's
/// own events (bounded: each tile moves 30 px) come on top.
std::uint64_t textured_scene_memory_bytes(const TexturedSceneSpec& spec);

/// The textured scene in a named pixel setting ("dvs", "dvs-dim": the
/// pixels and the background activity of apply_pixel_setting()).
/// False for an unknown name.
bool apply_pixel_setting(TexturedSceneSpec& spec, std::string_view name);

/// A generated scene served as a recording, from memory (the textured scene
/// is generated whole: ~70 bytes per event).
class SceneMemoryReader : public EventReader {
 public:
  explicit SceneMemoryReader(SyntheticScene scene) : scene_(std::move(scene)) {}

  std::size_t read(std::span<Event> out) override;
  /// Like read(), also copying the truth of each event (truth.size() >= out.size()).
  std::size_t read_with_truth(std::span<Event> out, std::span<EventTruth> truth);

  std::optional<SensorSize> sensor_size() const override { return scene_.spec.sensor; }
  std::string_view format_name() const override { return "synthetic"; }
  const std::string& path() const override { return name_; }
  const SyntheticScene& scene() const noexcept { return scene_; }

 private:
  SyntheticScene scene_;
  std::string name_ = "<synthetic>";
  std::size_t next_ = 0;
};

}  // namespace evlife::io
