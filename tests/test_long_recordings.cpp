// Recordings longer than the accuracy scenes' 0.6-2 s: a camera that watches
// a static scene for seconds (a hovering drone) fires only background
// activity, and the estimator must not drift into labelling it edges. Two
// defaults keep it from doing so, and each alone fails this test:
// - the tolerance floor follows the window's median residual of recent fits
//   (window_noise.h). With the mean, fits through noise widened the floor,
//   which passed more noise: 77 % of it in the 7th second here, edges
//   afterwards 24x too long; with max_lifetime_us at 0.3 s too the decline
//   is slower but goes on (99.2 % labelled noise from 3 s on, 97.7 % in the
//   8th second, 96.4 % of the noise among the edges after it);
// - max_lifetime_us = 0.3 s. With 1 s, planes through background activity
//   pass once every pixel has fired (96.8 % labelled noise from 3 s on).
// Default options throughout.
#include <gtest/gtest.h>

#include <cstdint>
#include <iostream>
#include <vector>

#include "accuracy_metrics.h"
#include "evlife/algo/lifetime_estimator.h"
#include "evlife/io/synthetic_scene.h"

namespace {

using evlife::AugmentedEvent;
using evlife::io::SyntheticScene;

// The events (and their truth) with t in [begin_us, end_us).
SyntheticScene slice(const SyntheticScene& scene, std::int64_t begin_us, std::int64_t end_us,
                     std::vector<AugmentedEvent>& out) {
  SyntheticScene part;
  part.spec = scene.spec;
  part.feature_names = scene.feature_names;
  std::vector<AugmentedEvent> kept;
  for (std::size_t i = 0; i < scene.events.size(); ++i) {
    if (scene.events[i].t_us < begin_us || scene.events[i].t_us >= end_us) continue;
    part.events.push_back(scene.events[i]);
    part.truth.push_back(scene.truth[i]);
    kept.push_back(out[i]);
  }
  out = std::move(kept);
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

  evlife::LifetimeOptions options;
  options.sensor = spec.sensor;
  evlife::LifetimeEstimator estimator(options);
  std::vector<AugmentedEvent> out(scene.events.size());
  ASSERT_EQ(estimator.process(scene.events, out), out.size());

  // Background activity only, after the surface has filled (3 s: 95 % of
  // the pixels have fired at 1 Hz) and until the edges start (jitter may
  // put their first events up to 80 us early).
  std::vector<AugmentedEvent> static_out = out;
  const SyntheticScene static_part = slice(scene, 3'000'000, edges_begin_us - 1'000, static_out);
  std::size_t static_noise = 0, static_labelled_noise = 0;
  for (std::size_t i = 0; i < static_part.events.size(); ++i) {
    ASSERT_TRUE(static_part.truth[i].is_noise);
    ++static_noise;
    static_labelled_noise += static_out[i].lifetime_us <= 0.0f;
  }
  ASSERT_GT(static_noise, 100'000u);
  const double static_share = static_cast<double>(static_labelled_noise) / static_cast<double>(static_noise);
  std::cout << "background activity after 3 s: " << 100.0 * static_share << " % labelled noise\n";
  EXPECT_GE(static_share, 0.995);
  // And no drift: the last second before the edges as clean.
  std::vector<AugmentedEvent> last_out = out;
  slice(scene, edges_begin_us - 1'001'000, edges_begin_us - 1'000, last_out);
  std::size_t last_labelled_noise = 0;
  for (const AugmentedEvent& a : last_out) last_labelled_noise += a.lifetime_us <= 0.0f;
  ASSERT_GT(last_out.size(), 30'000u);
  EXPECT_GE(static_cast<double>(last_labelled_noise) / static_cast<double>(last_out.size()), 0.995);

  std::vector<AugmentedEvent> edges_out = out;
  const SyntheticScene edges_part = slice(scene, edges_begin_us, kDurationUs, edges_out);
  const auto report = evlife::test::evaluate_accuracy(edges_part, edges_out);
  std::cout << evlife::test::format_accuracy_table("edges after 6 s of background activity", report);
  const auto& o = report.overall;
  ASSERT_GT(o.edge_events, 100'000u);
  EXPECT_GE(o.lifetime_share, 0.95);
  EXPECT_LE(o.median_rel_error, 0.02);  // 23.3 (2,335 %) with the mean
  EXPECT_LE(o.p90_rel_error, 0.10);
  EXPECT_GE(o.noise_share, 0.97);  // the noise floor
}

// Ten times the top of room-temperature background activity (a dark scene,
// a hot sensor): the floor must not run away either. Without
// kMinTimingNoiseSamples (lifetime_estimator.cpp), continuations of 4-5
// samples stored residuals through noise, the window medians rose, and the
// share labelled noise fell 96.0, 90.5, 75.4, 45.7, 25.5 % by second.
TEST(LongRecordings, HeavyBackgroundActivityDoesNotRunAway) {
  evlife::io::SceneSpec spec;
  spec.sensor = {120, 90};
  spec.duration_us = 6'000'000;
  spec.noise_rate_hz_per_px = 10.0;
  spec.seed = 9;
  const SyntheticScene scene = evlife::io::generate_scene(spec);
  evlife::LifetimeOptions options;
  options.sensor = spec.sensor;
  evlife::LifetimeEstimator estimator(options);
  std::vector<AugmentedEvent> out(scene.events.size());
  ASSERT_EQ(estimator.process(scene.events, out), out.size());
  for (std::int64_t second = 0; second < 6; ++second) {
    std::size_t events = 0, labelled_noise = 0;
    for (std::size_t i = 0; i < out.size(); ++i) {
      if (scene.events[i].t_us / 1'000'000 != second) continue;
      ASSERT_TRUE(scene.truth[i].is_noise);
      ++events;
      labelled_noise += out[i].lifetime_us <= 0.0f;
    }
    ASSERT_GT(events, 50'000u);
    const double share = static_cast<double>(labelled_noise) / static_cast<double>(events);
    std::cout << "second " << second << ": " << 100.0 * share << " % labelled noise\n";
    // 93.0-96.0 % measured; not the 99.9 % of 1 Hz/px: at 10 Hz/px a 0.3 s
    // plane's +-0.09 s band holds 1.8 noise events per pixel on average.
    EXPECT_GE(share, 0.90) << "second " << second;
  }
}

}  // namespace
