#include "accuracy_scenes.h"

#include <cstdio>
#include <cstdlib>
#include <utility>

namespace evlife::test {
namespace {

template <typename Spec>
Spec with_setting(Spec spec, const char* setting) {
  if (!io::apply_pixel_setting(spec, setting)) {  // a name in this file, not input
    std::fprintf(stderr, "accuracy_scenes: no pixel setting %s\n", setting);
    std::abort();
  }
  return spec;
}

AccuracyScene with_pixels(std::string title, io::SceneSpec spec, const char* setting) {
  return {std::move(title) + ", " + setting + " pixels", with_setting(std::move(spec), setting), std::nullopt};
}

AccuracyScene textured(unsigned seed, const char* setting) {
  io::TexturedSceneSpec t;
  t.sensor = {346, 260};
  t.duration_us = 600'000;
  t.seed = seed;
  return {std::string("dead leaves 346x260, 0.6 s, ") + setting + " pixels", {}, with_setting(t, setting)};
}

}  // namespace

std::vector<AccuracyScene> ideal_accuracy_scenes(unsigned seed_offset) {
  const unsigned s = seed_offset;
  return {{"edges 240x180, 0.8 s", io::edges_scene({240, 180}, 800'000, 1 + s), std::nullopt},
          {"edges 346x260, 0.6 s", io::edges_scene({346, 260}, 600'000, 2 + s, 4), std::nullopt},
          {"rotating bar 240x180, 150->1200 deg/s in 1 s", io::rotating_bar_scene({240, 180}, 1'000'000, 3 + s),
           std::nullopt},
          {"rotating bar 346x260, 150->1200 deg/s in 0.6 s", io::rotating_bar_scene({346, 260}, 600'000, 4 + s),
           std::nullopt},
          {"mixed 128x128, 2 s", io::mixed_scene({128, 128}, 2'000'000, 5 + s), std::nullopt}};
}

std::vector<AccuracyScene> pixel_model_accuracy_scenes(unsigned seed_offset) {
  const unsigned s = seed_offset;
  const char* const bar = "rotating bar 346x260, 150->1200 deg/s in 0.6 s";
  return {with_pixels("edges 346x260, 0.6 s", io::edges_scene({346, 260}, 600'000, 11 + s, 4), "dvs"),
          with_pixels(bar, io::rotating_bar_scene({346, 260}, 600'000, 12 + s), "dvs"),
          with_pixels("edges 346x260, 0.6 s", io::edges_scene({346, 260}, 600'000, 13 + s, 4), "dvs-dim"),
          with_pixels(bar, io::rotating_bar_scene({346, 260}, 600'000, 14 + s), "dvs-dim")};
}

std::vector<AccuracyScene> textured_accuracy_scenes(unsigned seed_offset) {
  return {textured(21 + seed_offset, "dvs"), textured(22 + seed_offset, "dvs-dim")};
}

void make_pixels_near_ideal(io::TexturedSceneSpec& spec) {
  spec.noise_rate_hz_per_px = 0.0;
  spec.pixel.hot_pixel_fraction = 0.0;
  spec.pixel.latency_us = 0.0;
  spec.pixel.latency_jitter_us = 0.0;
  spec.pixel.refractory_us = 0.0;
  spec.pixel.threshold_mismatch_sigma = 0.0;
}

}  // namespace evlife::test
