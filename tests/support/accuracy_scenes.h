// The synthetic scenes whose accuracy the README quotes, defined once:
// test_lifetime_accuracy asserts the floors on them, bench/accuracy_sweep
// prints the same figures for other options or seeds.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "evlife/io/synthetic_scene.h"
#include "evlife/io/textured_scene.h"

namespace evlife::test {

struct AccuracyScene {
  std::string title;
  io::SceneSpec spec;  ///< with the pixel setting applied
  /// Set for a textured scene: then it, not `spec`, defines the scene.
  std::optional<io::TexturedSceneSpec> textured;

  io::PixelModel& pixel() { return textured ? textured->pixel : spec.pixel; }
  double& noise_rate_hz_per_px() { return textured ? textured->noise_rate_hz_per_px : spec.noise_rate_hz_per_px; }
  io::SyntheticScene generate() const {
    return textured ? io::generate_textured_scene(*textured) : io::generate_scene(spec);
  }
};

/// Ideal pixels: edges 240x180 and 346x260, rotating bar 240x180 and
/// 346x260, mixed 128x128. `seed_offset` is added to every scene's seed.
std::vector<AccuracyScene> ideal_accuracy_scenes(unsigned seed_offset = 0);

/// Realistic DVS pixels, DAVIS346: edges and rotating bar in normal light
/// (`dvs`), then the same in dim light (`dvs-dim`).
std::vector<AccuracyScene> pixel_model_accuracy_scenes(unsigned seed_offset = 0);

/// Realistic DVS pixels, DAVIS346, on a translating dead-leaves texture
/// (textured_scene.h): normal light, then dim light.
std::vector<AccuracyScene> textured_accuracy_scenes(unsigned seed_offset = 0);

/// The texture's pixels without the sensor's imperfections: no background
/// activity, hot pixels, latency, jitter, refractory period or threshold
/// mismatch (the threshold itself unchanged).
void make_pixels_near_ideal(io::TexturedSceneSpec& spec);

}  // namespace evlife::test
