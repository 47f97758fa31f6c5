// Recordings longer than the accuracy scenes' 0.6-2 s: a camera that watches
// a static scene for seconds (a hovering drone) fires only background
// activity, and the estimator must not drift into labelling it edges. Three
// defaults keep it from doing so; without any one of them a test here fails:
// - the tolerance floor follows the window's median residual of recent fits
//   (window_noise.h). With the mean, fits through noise widened the floor,
//   which passed more noise: 77 % of it in the 7th second here, edges
//   afterwards 24x too long; with max_lifetime_us at 0.3 s too the decline
//   is slower but goes on (99.2 % labelled noise from 3 s on, 97.7 % in the
//   8th second, 96.4 % of the noise among the edges after it);
// - max_lifetime_us = 0.3 s. With 1 s, planes through background activity
//   pass once every pixel has fired (96.8 % labelled noise from 3 s on);
// - only fits of >= 6 samples store their residual (second test).
// And a scene that moves all along, in dim light, keeps the floors
// second by second (third test). Default options throughout.
#include <gtest/gtest.h>

#include <cstdint>
#include <iostream>
#include <utility>
#include <vector>

#include "accuracy_metrics.h"
#include "config_presets.h"
#include "evlife/algo/lifetime_estimator.h"
#include "evlife/io/synthetic_scene.h"

namespace {

using evlife::AugmentedEvent;
using evlife::io::SyntheticScene;

// The estimator's output for every event of the scene (default options
// unless given).
std::vector<AugmentedEvent> estimate(const SyntheticScene& scene, evlife::LifetimeOptions options = {}) {
  options.sensor = scene.spec.sensor;
  evlife::LifetimeEstimator estimator(options);
  std::vector<AugmentedEvent> out(scene.events.size());
  EXPECT_EQ(estimator.process(scene.events, out), out.size());
  return out;
}

// Share labelled noise of the events with t in [begin_us, end_us), which
// must all be noise (at least min_events of them).
double labelled_noise_share(const SyntheticScene& scene, const std::vector<AugmentedEvent>& out,
                            std::int64_t begin_us, std::int64_t end_us, std::size_t min_events) {
  std::size_t events = 0, labelled_noise = 0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (scene.events[i].t_us < begin_us || scene.events[i].t_us >= end_us) continue;
    EXPECT_TRUE(scene.truth[i].is_noise) << "event " << i;
    ++events;
    labelled_noise += out[i].lifetime_us <= 0.0f;
  }
  EXPECT_GE(events, min_events);
  return events == 0 ? 0.0 : static_cast<double>(labelled_noise) / static_cast<double>(events);
}

// The events (and their truth and output) with t in [begin_us, end_us).
std::pair<SyntheticScene, std::vector<AugmentedEvent>> slice(const SyntheticScene& scene,
                                                             const std::vector<AugmentedEvent>& out,
                                                             std::int64_t begin_us, std::int64_t end_us) {
  std::pair<SyntheticScene, std::vector<AugmentedEvent>> part;
  part.first.spec = scene.spec;
  part.first.feature_names = scene.feature_names;
  for (std::size_t i = 0; i < scene.events.size(); ++i) {
    if (scene.events[i].t_us < begin_us || scene.events[i].t_us >= end_us) continue;
    part.first.events.push_back(scene.events[i]);
    part.first.truth.push_back(scene.truth[i]);
    part.second.push_back(out[i]);
  }
  return part;
}

// 7 s of background activity alone at 1 Hz per pixel (the dim-light rate of
// the pixel model, the top of what DVS128 and DAVIS report at room
// temperature), then the edge tiles of the accuracy scenes for their last
// six passes. Ideal pixels: the edges' floors are the ideal scenes' ones.
TEST(LongRecordings, BackgroundActivityStaysNoiseAndEdgesAfterItKeepTheirAccuracy) {
  constexpr std::int64_t kDurationUs = 8'000'000;
  auto spec = evlife::io::edges_scene({240, 180}, kDurationUs, 9);
  spec.noise_rate_hz_per_px = 1.0;
  std::int64_t edges_begin_us = kDurationUs;
  for (const auto& g : spec.gratings) edges_begin_us = std::min(edges_begin_us, g.t_begin_us);
  ASSERT_GT(edges_begin_us, 6'000'000) << "the scene must start with seconds of background activity alone";
  const SyntheticScene scene = evlife::io::generate_scene(spec);
  const std::vector<AugmentedEvent> out = estimate(scene);

  // Background activity only, after the surface has filled (3 s: 95 % of
  // the pixels have fired at 1 Hz) and until the edges start (jitter may
  // put their first events up to 80 us early).
  const std::int64_t static_end_us = edges_begin_us - 1'000;
  for (std::int64_t t = 0; t + 1'000'000 <= static_end_us; t += 1'000'000) {
    std::cout << "second " << t / 1'000'000 << ": "
              << 100.0 * labelled_noise_share(scene, out, t, t + 1'000'000, 30'000) << " % labelled noise\n";
  }
  const double static_share = labelled_noise_share(scene, out, 3'000'000, static_end_us, 100'000);
  std::cout << "background activity after 3 s: " << 100.0 * static_share << " % labelled noise\n";
  EXPECT_GE(static_share, 0.995);
  // And no drift: the last second before the edges as clean.
  EXPECT_GE(labelled_noise_share(scene, out, static_end_us - 1'000'000, static_end_us, 30'000), 0.995);

  const auto [edges_part, edges_out] = slice(scene, out, edges_begin_us, kDurationUs);
  const auto report = evlife::test::evaluate_accuracy(edges_part, edges_out);
  std::cout << evlife::test::format_accuracy_table("edges after 6 s of background activity", report);
  const auto& o = report.overall;
  ASSERT_GT(o.edge_events, 100'000u);
  EXPECT_GE(o.lifetime_share, 0.95);
  EXPECT_LE(o.median_rel_error, 0.02);  // 23.3 (2,335 %) with the mean
  EXPECT_LE(o.p90_rel_error, 0.10);
  EXPECT_GE(o.noise_share, 0.97);  // the noise floor
}

// 6 s of a static 120 x 90 scene: background activity alone.
SyntheticScene static_background(double rate_hz_per_px) {
  evlife::io::SceneSpec spec;
  spec.sensor = {120, 90};
  spec.duration_us = 6'000'000;
  spec.noise_rate_hz_per_px = rate_hz_per_px;
  spec.seed = 9;
  return evlife::io::generate_scene(spec);
}

// Ten times the top of room-temperature background activity (a dark scene,
// a hot sensor): the floor must not run away either. Without
// kMinTimingNoiseSamples (lifetime_estimator.cpp), continuations of 4-5
// samples stored residuals through noise, the window medians rose, and the
// share labelled noise fell 96.0, 90.5, 75.4, 45.7, 25.5 % by second.
TEST(LongRecordings, HeavyBackgroundActivityDoesNotRunAway) {
  const SyntheticScene scene = static_background(10.0);
  const std::vector<AugmentedEvent> out = estimate(scene);
  for (std::int64_t second = 0; second < 6; ++second) {
    const double share = labelled_noise_share(scene, out, second * 1'000'000, (second + 1) * 1'000'000, 50'000);
    std::cout << "second " << second << ": " << 100.0 * share << " % labelled noise\n";
    // 91.7-95.5 % measured (93.0-96.0 % before followers chained,
    // lifetime_options.h burst_span_lifetimes); not the 99.9 % of 1 Hz/px: at 10 Hz/px a 0.3 s
    // plane's +-0.09 s band holds 1.8 noise events per pixel on average.
    EXPECT_GE(share, 0.90) << "second " << second;
  }
}

// config/faint-texture.yaml (a +-0.4 lifetime band with the offset check)
// claims sensors with at most ~1 Hz/px of background activity (the top of
// room temperature): there a static scene must stay noise second by second,
// with no drift. Measured 99.5-99.9 % (defaults 99.8-99.95 %). Beyond, the
// preset gives way: at 1.5 / 2 Hz/px 97.7-99.5 / 93.1-98.6 % (defaults
// 99.3-99.9 / 98.3-99.6 %), at 10 Hz/px it runs away (84.5 % in the first
// second, 26.5 % in the sixth; algo/README.md, *Faint texture, little background
// activity*).
TEST(LongRecordings, FaintTexturePresetHoldsBackgroundActivityAtItsLimit) {
  const SyntheticScene scene = static_background(1.0);
  const std::vector<AugmentedEvent> out = estimate(scene, evlife::test::faint_texture_preset());
  const std::vector<AugmentedEvent> with_defaults = estimate(scene);
  for (std::int64_t second = 0; second < 6; ++second) {
    const std::int64_t begin = second * 1'000'000, end = begin + 1'000'000;
    const double share = labelled_noise_share(scene, out, begin, end, 10'000);
    std::cout << "second " << second << ": " << 100.0 * share << " % labelled noise (defaults "
              << 100.0 * labelled_noise_share(scene, with_defaults, begin, end, 10'000) << " %)\n";
    EXPECT_GE(share, 0.99) << "second " << second;
  }
}

// Dim light (the pixel model's dvs-dim: latency jitter of hundreds of us,
// 1 Hz/px of background activity) for 8 s of the mixed scene, which moves
// all along: the accuracy scenes last 0.6 s, and a surface that has filled
// with fits for seconds must keep the dim-light floors in every
// second (noise near an edge event of its pixel not scored, as there).
// Measured: 98.2-99.5 % of the noise labelled noise by second, 99.1-99.97 %
// of edge events with a lifetime, p90 error 8.7-15.0 %. With max_lifetime_us
// at 1 s the same scene of `evlife synth` (seed 1) has 96.9-97.7 % labelled
// noise by tenth after the first.
TEST(LongRecordings, DimLightKeepsItsFloorsSecondBySecond) {
  constexpr std::int64_t kDurationUs = 8'000'000;
  auto spec = evlife::io::mixed_scene({240, 180}, kDurationUs, 3);
  ASSERT_TRUE(evlife::io::apply_pixel_setting(spec, "dvs-dim"));
  const SyntheticScene scene = evlife::io::generate_scene(spec);
  const std::vector<AugmentedEvent> out = estimate(scene);
  for (std::int64_t second = 0; second < kDurationUs / 1'000'000; ++second) {
    const auto [part, part_out] = slice(scene, out, second * 1'000'000, (second + 1) * 1'000'000);
    const auto report = evlife::test::evaluate_accuracy(part, part_out);
    const auto& o = report.overall;
    std::cout << "second " << second << ": " << 100.0 * o.lifetime_share << " % of edge events with a lifetime, median error "
              << 100.0 * o.median_rel_error << " %, p90 " << 100.0 * o.p90_rel_error << " %, noise labelled noise "
              << 100.0 * o.noise_share << " % (" << o.noise_events << ")\n";
    ASSERT_GT(o.edge_events, 50'000u);
    ASSERT_GT(o.noise_events, 20'000u);
    EXPECT_GE(o.lifetime_share, 0.85) << "second " << second;
    EXPECT_LE(o.median_rel_error, 0.10) << "second " << second;
    EXPECT_LE(o.p90_rel_error, 0.30) << "second " << second;
    EXPECT_GE(o.noise_share, 0.97) << "second " << second;
  }
}

}  // namespace
