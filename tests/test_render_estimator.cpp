// Rendering through the estimator: a synthetic grating with known motion is
// augmented by LifetimeEstimator, fed to ActiveEventMap and sampled at
// arbitrary instants. The ground truth is the scene's edge positions (not
// anything the renderer or estimator computes).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <tuple>
#include <numbers>
#include <vector>

#include "evlife/algo/lifetime_estimator.h"
#include "evlife/io/synthetic_scene.h"
#include "evlife/algo/active_event_map.h"
#include "evlife/render/augmented_source.h"
#include "evlife/render/fixed_window_map.h"
#include "evlife/render/render_cursor.h"

namespace {

using evlife::SensorSize;

struct EdgeStats {
  std::size_t active = 0;
  std::size_t on_edge = 0;      // signed distance in [-2, +0.5] px: the line is <= ~2 px thick
  std::size_t behind = 0;       // further than 3 px behind an edge: smear
  std::size_t expected = 0;     // pixels the edge swept during the last lifetime
  std::size_t expected_drawn = 0;
};

// Signed distance (px, along the motion) from the pixel centre to the nearest
// edge of the grating at time t: 0 = on the edge, negative = already passed.
double signed_distance(const evlife::io::GratingSpec& g, double s_px, double t_us) {
  double best = 1e9;
  for (int edge = 0; edge < 2; ++edge) {
    const double d = g.phase_px + t_us / g.lifetime_us - (edge == 0 ? 0.0 : g.bar_width_px);
    double r = std::fmod(s_px - d, g.period_px);
    if (r > g.period_px / 2) r -= g.period_px;
    if (r < -g.period_px / 2) r += g.period_px;
    if (std::fabs(r) < std::fabs(best)) best = r;
  }
  return best;
}

template <class Active>
EdgeStats measure(const evlife::io::GratingSpec& g, SensorSize sensor, double t_us, Active active) {
  const double nx = std::cos(g.direction_deg * std::numbers::pi / 180.0);
  const double ny = std::sin(g.direction_deg * std::numbers::pi / 180.0);
  EdgeStats st;
  const int margin = 4;  // the estimator's window needs neighbours
  for (int y = margin; y < sensor.height - margin; ++y)
    for (int x = margin; x < sensor.width - margin; ++x) {
      const double d = signed_distance(g, x * nx + y * ny, t_us);
      const bool on = active(x, y);
      if (d > -1.0 && d <= 0.0) {
        ++st.expected;
        st.expected_drawn += on ? 1 : 0;
      }
      if (!on) continue;
      ++st.active;
      if (d >= -2.0 && d <= 0.5) ++st.on_edge;
      if (d < -3.0) ++st.behind;
    }
  return st;
}

// Param: lifetime of the edge (us), edge thinning on/off. Off shows that the
// estimated lifetimes alone already keep a constant-speed edge thin.
class EdgeThroughEstimator : public ::testing::TestWithParam<std::tuple<double, bool>> {};

TEST_P(EdgeThroughEstimator, RendersAThinLineAtTheTrueEdgeWhateverTheSpeed) {
  const double lifetime_us = std::get<0>(GetParam());
  const bool thinning = std::get<1>(GetParam());
  const SensorSize sensor{96, 96};
  evlife::io::SceneSpec spec;
  spec.sensor = sensor;
  spec.duration_us = 400'000;
  spec.noise_rate_hz_per_px = 1.0;
  spec.jitter_sigma_us = std::min(20.0, lifetime_us / 20.0);
  evlife::io::GratingSpec g;
  g.direction_deg = 30.0;
  g.lifetime_us = lifetime_us;
  g.period_px = 40.0;
  g.bar_width_px = 20.0;
  spec.gratings.push_back(g);

  evlife::LifetimeOptions options;
  options.sensor = sensor;
  auto source = evlife::render::make_estimating_source(
      std::make_unique<evlife::io::SyntheticSceneReader>(spec), options);
  evlife::ActiveEventMap set(sensor, thinning);
  evlife::render::FixedWindowMap window(sensor);
  evlife::render::RenderCursor cursor(*source, set, &window);
  std::size_t checked = 0;
  // Arbitrary instants after a warm-up (the estimator needs history).
  for (const std::int64_t t : {151'337, 203'001, 287'777, 333'333, 391'019}) {
    cursor.advance_to(t);
    const auto st = measure(g, sensor, static_cast<double>(t),
                            [&](int x, int y) { return set.is_active(x, y, t); });
    SCOPED_TRACE("t = " + std::to_string(t) + " us, lifetime " + std::to_string(lifetime_us) + " us");
    ASSERT_GT(st.expected, 0u);
    // Complete enough to be an edge, not a few dots.
    EXPECT_GE(static_cast<double>(st.expected_drawn), 0.5 * static_cast<double>(st.expected));
    // Thin and in the right place.
    EXPECT_GE(static_cast<double>(st.on_edge), 0.9 * static_cast<double>(st.active));
    EXPECT_LE(static_cast<double>(st.behind), 0.05 * static_cast<double>(st.active));
    // The 30 ms window smears whenever the edge moves more than 3 px in 30 ms.
    if (30000.0 / lifetime_us > 6.0) {
      const auto w = measure(g, sensor, static_cast<double>(t), [&](int x, int y) {
        return window.is_active(static_cast<std::size_t>(y) * static_cast<std::size_t>(sensor.width) + static_cast<std::size_t>(x), t, 30000);
      });
      EXPECT_GT(w.behind, w.on_edge / 2) << "the 30 ms window should smear this edge";
    }
    ++checked;
  }
  EXPECT_EQ(checked, 5u);
}

INSTANTIATE_TEST_SUITE_P(Speeds, EdgeThroughEstimator,
                         ::testing::Combine(::testing::Values(500.0, 2000.0, 8000.0), ::testing::Bool()));

}  // namespace
