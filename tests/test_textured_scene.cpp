// The textured scene (io/textured_scene.h): a dead-leaves texture per tile,
// translating, sampled by DVS pixels. Deterministic, time-ordered, and the
// pixel's physics: events per threshold crossed, latency bounds, refractory
// period, background and hot-pixel rates; the truth bounded by the tiles'
// motion.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "accuracy_scenes.h"
#include "evlife/io/textured_scene.h"

namespace evlife {
namespace {

using io::SyntheticScene;
using io::TexturedSceneSpec;

TexturedSceneSpec small_spec() {
  TexturedSceneSpec s;
  s.sensor = {120, 120};  // 2 x 2 tiles of 60 px
  s.duration_us = 300'000;
  s.travel_px = 20.0;
  s.lifetime_min_us = 1000.0;
  s.lifetime_max_us = 8000.0;
  return s;
}

std::size_t edge_events(const SyntheticScene& scene) {
  return static_cast<std::size_t>(
      std::count_if(scene.truth.begin(), scene.truth.end(), [](const io::EventTruth& t) { return !t.is_noise; }));
}

TEST(TexturedScene, DeterministicOrderedAndInsideTheSensor) {
  const TexturedSceneSpec spec = small_spec();
  const SyntheticScene a = io::generate_textured_scene(spec);
  const SyntheticScene b = io::generate_textured_scene(spec);
  ASSERT_EQ(a.events.size(), a.truth.size());
  ASSERT_GT(a.events.size(), 10'000u);
  ASSERT_EQ(a.events.size(), b.events.size());
  EXPECT_EQ(std::memcmp(a.events.data(), b.events.data(), a.events.size() * sizeof(Event)), 0);
  EXPECT_EQ(a.feature_names.size(), 4u);
  std::size_t on = 0;
  for (std::size_t i = 0; i < a.events.size(); ++i) {
    const Event& e = a.events[i];
    ASSERT_LT(e.x, spec.sensor.width);
    ASSERT_LT(e.y, spec.sensor.height);
    ASSERT_TRUE(e.p == 1 || e.p == -1);
    ASSERT_GE(e.t_us, 0);
    ASSERT_LT(e.t_us, spec.duration_us);
    if (i > 0) {
      ASSERT_GE(e.t_us, a.events[i - 1].t_us) << i;
    }
    on += e.p > 0 ? 1 : 0;
    EXPECT_EQ(a.truth[i].t_true_us, b.truth[i].t_true_us);
  }
  // A texture moving over a pixel brightens it as often as it darkens it.
  const double on_share = static_cast<double>(on) / static_cast<double>(a.events.size());
  EXPECT_GT(on_share, 0.4);
  EXPECT_LT(on_share, 0.6);
  TexturedSceneSpec other = spec;
  other.seed = 2;
  const SyntheticScene c = io::generate_textured_scene(other);
  EXPECT_TRUE(c.events.size() != a.events.size() ||
              std::memcmp(a.events.data(), c.events.data(), a.events.size() * sizeof(Event)) != 0);
}

// Each event is stamped latency after its crossing (within the truncation),
// and no edge event of a pixel comes within the refractory period after the
// pixel's previous one (the reset is held that long after the stamp).
TEST(TexturedScene, LatencyAndRefractoryPeriod) {
  TexturedSceneSpec spec = small_spec();
  spec.pixel.latency_us = 100.0;
  spec.pixel.latency_jitter_us = 30.0;
  spec.pixel.refractory_us = 300.0;
  const SyntheticScene scene = io::generate_textured_scene(spec);
  std::map<std::pair<int, int>, double> last_stamp;
  std::size_t checked = 0;
  for (std::size_t i = 0; i < scene.events.size(); ++i) {
    const io::EventTruth& t = scene.truth[i];
    if (t.is_noise) continue;
    const auto stamp = static_cast<double>(scene.events[i].t_us);
    const double latency = stamp - t.t_true_us;
    EXPECT_GE(latency, -1.0) << i;  // stamps are floored to whole microseconds
    EXPECT_LE(latency, 100.0 + 4.0 * 30.0 + 1e-6) << i;
    const auto key = std::make_pair(int{scene.events[i].x}, int{scene.events[i].y});
    if (const auto it = last_stamp.find(key); it != last_stamp.end()) {
      EXPECT_GE(stamp - it->second, 300.0 - 1.0) << i;
      ++checked;
    }
    last_stamp[key] = stamp;
  }
  EXPECT_GT(checked, 5000u);
}

// One event per threshold crossed: with half the threshold (and no
// refractory period or latency to lose crossings) a pixel fires at least
// twice as often (a change of theta is two of theta / 2), and somewhat more:
// the texture's faint steps between theta / 2 and theta fire now (measured
// 2.5x).
TEST(TexturedScene, EventsScaleWithTheInverseThreshold) {
  TexturedSceneSpec spec = small_spec();
  test::make_pixels_near_ideal(spec);
  spec.pixel.threshold_log = 0.2;
  const double at_02 = static_cast<double>(edge_events(io::generate_textured_scene(spec)));
  spec.pixel.threshold_log = 0.1;
  const double at_01 = static_cast<double>(edge_events(io::generate_textured_scene(spec)));
  EXPECT_GT(at_01 / at_02, 1.9);
  EXPECT_LT(at_01 / at_02, 3.0);
}

// Background activity and hot pixels fire at their rates (Poisson: within
// 5 sigma), as noise in the truth.
TEST(TexturedScene, BackgroundAndHotPixelRates) {
  TexturedSceneSpec spec = small_spec();
  spec.noise_rate_hz_per_px = 2.0;
  spec.pixel.hot_pixel_fraction = 1e-3;
  spec.pixel.hot_pixel_rate_hz = 50.0;
  const SyntheticScene scene = io::generate_textured_scene(spec);
  std::size_t background = 0, hot = 0;
  for (const io::EventTruth& t : scene.truth) {
    if (!t.is_noise) continue;
    EXPECT_EQ(t.lifetime_us, 0.0);
    (t.is_hot ? hot : background) += 1;
  }
  const double seconds = static_cast<double>(spec.duration_us) * 1e-6;
  const double want_background = 2.0 * 120.0 * 120.0 * seconds;
  const double want_hot = std::round(1e-3 * 120 * 120) * 50.0 * seconds;
  EXPECT_NEAR(static_cast<double>(background), want_background, 5.0 * std::sqrt(want_background));
  EXPECT_NEAR(static_cast<double>(hot), want_hot, 5.0 * std::sqrt(want_hot));
}

// The truth of an edge event: its iso-line moves at most as fast as its
// tile (lifetime >= the tile's, equal where the edge is across the motion),
// the direction a unit vector; scored only where the lifetime is at most 3x
// the tile's; events from before a tile moves carry no score.
TEST(TexturedScene, TruthBoundedByTheTilesMotion) {
  const TexturedSceneSpec spec = small_spec();
  const SyntheticScene scene = io::generate_textured_scene(spec);
  std::size_t scorable = 0, moving = 0;
  for (const io::EventTruth& t : scene.truth) {
    if (t.is_noise) continue;
    ASSERT_GE(t.feature, 0);
    ASSERT_LT(static_cast<std::size_t>(t.feature), scene.feature_names.size());
    EXPECT_GE(t.lifetime_us, spec.lifetime_min_us * (1.0 - 1e-9));
    if (t.nx != 0.0 || t.ny != 0.0) {
      ++moving;
      EXPECT_NEAR(std::hypot(t.nx, t.ny), 1.0, 1e-9);
    }
    if (t.scorable) {
      ++scorable;
      EXPECT_LE(t.lifetime_us, 3.0 * spec.lifetime_max_us * (1.0 + 1e-9));
      EXPECT_GT(t.travel_px, 0.0);
      EXPECT_LE(t.travel_px, spec.travel_px + 1e-9);
    }
  }
  EXPECT_GT(moving, 10'000u);
  EXPECT_GT(scorable, moving / 10);
}

TEST(TexturedScene, MemoryReaderServesTheSceneInChunks) {
  const SyntheticScene scene = io::generate_textured_scene(small_spec());
  io::SceneMemoryReader reader(scene);
  ASSERT_EQ(reader.sensor_size(), scene.spec.sensor);
  std::vector<Event> chunk(777);
  std::vector<io::EventTruth> truth(777);
  std::size_t at = 0;
  while (const std::size_t n = reader.read_with_truth(chunk, truth)) {
    ASSERT_LE(at + n, scene.events.size());
    EXPECT_EQ(std::memcmp(chunk.data(), scene.events.data() + at, n * sizeof(Event)), 0);
    EXPECT_EQ(truth[n - 1].t_true_us, scene.truth[at + n - 1].t_true_us);
    at += n;
  }
  EXPECT_EQ(at, scene.events.size());
}

TEST(TexturedScene, BadSpecsNameTheField) {
  const auto message = [](const TexturedSceneSpec& s) {
    try {
      io::generate_textured_scene(s);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  TexturedSceneSpec s = small_spec();
  s.tile_px = 4;
  EXPECT_NE(message(s).find("tile_px"), std::string::npos);
  s = small_spec();
  s.pixel.enabled = false;
  EXPECT_NE(message(s).find("pixel"), std::string::npos);
  s = small_spec();
  s.lifetime_max_us = s.lifetime_min_us / 2;
  EXPECT_NE(message(s).find("lifetime"), std::string::npos);
  s = small_spec();
  s.leaf_radius_min_px = 0.1;
  EXPECT_NE(message(s).find("leaf_radius"), std::string::npos);
  s = small_spec();
  s.tile_px = 1000;
  s.travel_px = 600.0;
  EXPECT_NE(message(s).find("texture memory"), std::string::npos);
  s = small_spec();
  s.texture_contrast_log = -1.0;
  EXPECT_NE(message(s).find("texture_contrast_log"), std::string::npos);
}

}  // namespace
}  // namespace evlife
