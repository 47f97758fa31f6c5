// Accuracy of the lifetime estimator on synthetic scenes with known ground
// truth (issue 2, "What it must reach"), with the DEFAULT LifetimeOptions
// (only the sensor set). The ground truth and the metric are tested first and
// independently, so a generator or metric bug cannot make the floors pass.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <iostream>
#include <map>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "accuracy_metrics.h"
#include "accuracy_scenes.h"
#include "config_presets.h"
#include "evlife/algo/lifetime_estimator.h"
#include "evlife/io/synthetic_scene.h"
#include "rejection_breakdown.h"

namespace {

using evlife::AugmentedEvent;
using evlife::Event;
using evlife::SensorSize;
using evlife::io::EventTruth;
using evlife::io::SceneSpec;
using evlife::io::SyntheticScene;
constexpr double kPi = std::numbers::pi;

// ---------------------------------------------------------------------------
// Ground truth: the generator's events are exactly the brightness transitions
// of the scene, and its lifetime/direction agree with the event-time field.
// ---------------------------------------------------------------------------

// Brightness (inside a bar?) of pixel (x, y) at time t, straight from the
// scene's definition, sampled by brute force below.
bool grating_bright(const evlife::io::GratingSpec& g, int x, int y, double t_us) {
  const double th = g.direction_deg * kPi / 180.0;
  const double s = x * std::cos(th) + y * std::sin(th);
  const double leading = g.phase_px + t_us / g.lifetime_us;  // a leading edge position
  const double behind = std::fmod(std::fmod(leading - s, g.period_px) + g.period_px, g.period_px);
  return behind <= g.bar_width_px;  // the bar spans [leading - width, leading]
}

// Caches the bar's axis for the current time: the brute-force loop asks for
// every sampled pixel at the same t.
class BarBrightness {
 public:
  explicit BarBrightness(const evlife::io::RotatingBarSpec& b) : b_(b) {}
  bool operator()(int x, int y, double t_us) {
    if (t_us != t_us_) {
      const double w0 = b_.omega_start_deg_s * kPi / 180.0 * 1e-6;
      const double w1 = b_.omega_end_deg_s * kPi / 180.0 * 1e-6;
      const double tr = std::min(t_us, b_.ramp_us);
      double phi = b_.start_angle_deg * kPi / 180.0 + w0 * tr + 0.5 * (w1 - w0) / b_.ramp_us * tr * tr;
      phi += w1 * std::max(0.0, t_us - b_.ramp_us);
      sin_ = std::sin(phi);
      cos_ = std::cos(phi);
      t_us_ = t_us;
    }
    const double dist = -sin_ * (x - b_.centre_x) + cos_ * (y - b_.centre_y);  // to the bar axis
    return std::abs(dist) <= 0.5 * b_.bar_width_px;
  }

 private:
  evlife::io::RotatingBarSpec b_;
  double t_us_ = -1.0, sin_ = 0.0, cos_ = 1.0;
};

struct Transition {
  double t_lo_us, t_hi_us;  // the transition happened in (t_lo, t_hi]
  int polarity;
};

// Samples brightness every dt and checks that each pixel's events are exactly
// its transitions (count, order, polarity, time within the sampling step).
template <typename Bright>
void expect_events_are_transitions(const SyntheticScene& scene, Bright bright, int pixel_stride,
                                   std::size_t min_checked) {
  ASSERT_EQ(scene.spec.jitter_sigma_us, 0.0);
  ASSERT_EQ(scene.spec.noise_rate_hz_per_px, 0.0);
  const SensorSize s = scene.spec.sensor;
  std::map<std::pair<int, int>, std::vector<std::size_t>> events_at;
  for (std::size_t i = 0; i < scene.events.size(); ++i) {
    events_at[{scene.events[i].x, scene.events[i].y}].push_back(i);
  }
  std::vector<std::pair<int, int>> pixels;
  for (int y = 1; y < s.height; y += pixel_stride) {
    for (int x = 2; x < s.width; x += pixel_stride) pixels.emplace_back(x, y);
  }
  const double dt = 2.0;
  std::vector<std::vector<Transition>> transitions(pixels.size());
  std::vector<bool> state(pixels.size());
  for (std::size_t k = 0; k < pixels.size(); ++k) state[k] = bright(pixels[k].first, pixels[k].second, 0.0);
  const auto steps = static_cast<long>(static_cast<double>(scene.spec.duration_us) / dt);
  for (long j = 1; j < steps; ++j) {
    const double t = static_cast<double>(j) * dt;
    for (std::size_t k = 0; k < pixels.size(); ++k) {
      const bool now = bright(pixels[k].first, pixels[k].second, t);
      if (now != state[k]) transitions[k].push_back({t - dt, t, now ? 1 : -1});
      state[k] = now;
    }
  }
  std::size_t checked = 0;
  for (std::size_t k = 0; k < pixels.size(); ++k) {
    const auto& idx = events_at[pixels[k]];
    const auto& tr = transitions[k];
    // Crossings in the last, unsampled step of the scene may be missing from `tr`.
    ASSERT_GE(idx.size(), tr.size()) << "pixel " << pixels[k].first << "," << pixels[k].second;
    ASSERT_LE(idx.size(), tr.size() + 1) << "pixel " << pixels[k].first << "," << pixels[k].second;
    for (std::size_t m = 0; m < tr.size(); ++m) {
      const Event& e = scene.events[idx[m]];
      const double t_true = scene.truth[idx[m]].t_true_us;
      EXPECT_EQ(e.p, tr[m].polarity) << "pixel " << e.x << "," << e.y << " transition " << m;
      EXPECT_GT(t_true, tr[m].t_lo_us - 1e-6);
      EXPECT_LE(t_true, tr[m].t_hi_us + 1e-6);
      EXPECT_LE(std::abs(static_cast<double>(e.t_us) - t_true), 0.5 + 1e-9);
      ++checked;
    }
  }
  EXPECT_GT(checked, min_checked);
}

// Central differences of the crossing times of the 4 neighbours (same pass,
// same polarity) give the time gradient: |grad| must be the true lifetime and
// grad/|grad| the true direction of motion.
struct GradientCheck {
  std::vector<double> rel_error, dir_error_deg;
};
GradientCheck gradient_check(const SyntheticScene& scene) {
  const SensorSize s = scene.spec.sensor;
  std::vector<std::vector<std::pair<double, double>>> times(2 * static_cast<std::size_t>(s.pixel_count()));
  auto slot = [&](int x, int y, int p) {
    return (static_cast<std::size_t>(y) * static_cast<std::size_t>(s.width) + static_cast<std::size_t>(x)) * 2 +
           (p > 0 ? 1 : 0);
  };
  for (std::size_t i = 0; i < scene.events.size(); ++i) {
    const Event& e = scene.events[i];
    times[slot(e.x, e.y, e.p)].push_back({scene.truth[i].t_true_us, scene.truth[i].lifetime_us});
  }
  for (auto& v : times) std::sort(v.begin(), v.end());
  GradientCheck out;
  for (std::size_t i = 0; i < scene.events.size(); ++i) {
    const Event& e = scene.events[i];
    const EventTruth& truth = scene.truth[i];
    if (truth.is_noise || !truth.scorable || truth.margin_px < 1) continue;
    auto nearest = [&](int x, int y, double& t) {
      const auto& v = times[slot(x, y, e.p)];
      auto it = std::lower_bound(v.begin(), v.end(), std::pair{truth.t_true_us, 0.0});
      double best = 1e300;
      if (it != v.end()) best = it->first;
      if (it != v.begin() && std::abs(std::prev(it)->first - truth.t_true_us) < std::abs(best - truth.t_true_us))
        best = std::prev(it)->first;
      t = best;
      return std::abs(best - truth.t_true_us) < 2.0 * truth.lifetime_us;
    };
    double tl, tr, tu, td;
    if (!nearest(e.x - 1, e.y, tl) || !nearest(e.x + 1, e.y, tr) || !nearest(e.x, e.y - 1, tu) ||
        !nearest(e.x, e.y + 1, td)) {
      continue;
    }
    const double gx = 0.5 * (tr - tl), gy = 0.5 * (td - tu);
    const double g = std::hypot(gx, gy);
    out.rel_error.push_back(std::abs(g - truth.lifetime_us) / truth.lifetime_us);
    const double c = (gx * truth.nx + gy * truth.ny) / g;
    out.dir_error_deg.push_back(std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / kPi);
  }
  return out;
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

SceneSpec clean(SceneSpec spec) {
  spec.jitter_sigma_us = 0.0;
  spec.noise_rate_hz_per_px = 0.0;
  return spec;
}

TEST(SyntheticGroundTruth, GratingEventsAreTheBrightnessTransitions) {
  SceneSpec spec;
  spec.sensor = {64, 48};
  spec.duration_us = 60'000;
  evlife::io::GratingSpec g;
  g.direction_deg = 217.0;
  g.lifetime_us = 700.0;
  g.period_px = 12.0;
  g.bar_width_px = 5.0;
  g.phase_px = 1.3;
  spec.gratings = {g};
  const SyntheticScene scene = evlife::io::generate_scene(clean(spec));
  expect_events_are_transitions(
      scene, [&](int x, int y, double t) { return grating_bright(g, x, y, t); }, 5, 1000);
}

TEST(SyntheticGroundTruth, RotatingBarEventsAreTheBrightnessTransitions) {
  const SyntheticScene scene =
      evlife::io::generate_scene(clean(evlife::io::rotating_bar_scene({60, 44}, 400'000, 3)));
  expect_events_are_transitions(scene, BarBrightness(scene.spec.bars.at(0)), 3, 800);
}

TEST(SyntheticGroundTruth, LifetimeAndDirectionMatchTheEventTimeGradient) {
  {  // straight edges: the time field is exactly planar
    const auto check = gradient_check(evlife::io::generate_scene(clean(evlife::io::edges_scene({240, 180}, 300'000, 1))));
    ASSERT_GT(check.rel_error.size(), 20000u);
    EXPECT_LT(quantile(check.rel_error, 1.0), 1e-6);
    EXPECT_LT(quantile(check.dir_error_deg, 1.0), 1e-3);
  }
  {  // rotating, accelerating bar: planar to first order away from the centre
    const auto check = gradient_check(evlife::io::generate_scene(clean(evlife::io::rotating_bar_scene({240, 180}, 500'000, 1))));
    ASSERT_GT(check.rel_error.size(), 20000u);
    // (Observed: p99 0.1 % and 0.05 deg. Using r instead of the arm length
    // sqrt(r^2 - (w/2)^2) would be off by > 0.5 % for r < 35 px: caught.)
    EXPECT_LT(quantile(check.rel_error, 0.5), 0.0005);
    EXPECT_LT(quantile(check.rel_error, 0.99), 0.005);
    EXPECT_LT(quantile(check.dir_error_deg, 0.5), 0.05);
    EXPECT_LT(quantile(check.dir_error_deg, 0.99), 0.5);
  }
}

TEST(SyntheticGroundTruth, JitterNoiseOrderAndDeterminism) {
  const SceneSpec spec = evlife::io::mixed_scene({128, 128}, 500'000, 42);
  const SyntheticScene a = evlife::io::generate_scene(spec);
  ASSERT_EQ(a.events.size(), a.truth.size());
  ASSERT_GT(a.events.size(), 10000u);
  // Time-ordered, inside the sensor, polarity +-1.
  for (std::size_t i = 0; i < a.events.size(); ++i) {
    if (i > 0) {
      ASSERT_LE(a.events[i - 1].t_us, a.events[i].t_us) << i;
    }
    ASSERT_TRUE(spec.sensor.contains(a.events[i].x, a.events[i].y));
    ASSERT_TRUE(a.events[i].p == 1 || a.events[i].p == -1);
  }
  // Jitter: Gaussian sigma 20 us, truncated at 4 sigma.
  double sum2 = 0.0, max_abs = 0.0;
  std::size_t edges = 0, noise = 0;
  for (std::size_t i = 0; i < a.events.size(); ++i) {
    if (a.truth[i].is_noise) {
      ++noise;
      continue;
    }
    const double d = static_cast<double>(a.events[i].t_us) - a.truth[i].t_true_us;
    sum2 += d * d;
    max_abs = std::max(max_abs, std::abs(d));
    ++edges;
  }
  const double sigma = std::sqrt(sum2 / static_cast<double>(edges));
  EXPECT_NEAR(sigma, 20.0, 1.0);
  EXPECT_LE(max_abs, 80.5);
  // Noise: 1 event per pixel per second.
  const double expected_noise = 128.0 * 128.0 * 0.5;
  EXPECT_NEAR(static_cast<double>(noise), expected_noise, 0.03 * expected_noise);
  // Deterministic, seed-dependent, and streaming gives the same as in memory.
  const SyntheticScene b = evlife::io::generate_scene(spec);
  ASSERT_EQ(a.events.size(), b.events.size());
  EXPECT_EQ(0, std::memcmp(a.events.data(), b.events.data(), a.events.size() * sizeof(Event)));
  SceneSpec other = spec;
  other.seed = 43;
  const SyntheticScene c = evlife::io::generate_scene(other);
  EXPECT_TRUE(c.events.size() != a.events.size() ||
              std::memcmp(a.events.data(), c.events.data(), a.events.size() * sizeof(Event)) != 0);
  evlife::io::SyntheticSceneReader reader(spec);
  std::vector<Event> streamed, buf(777);
  while (const std::size_t n = reader.read(buf)) streamed.insert(streamed.end(), buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n));
  ASSERT_EQ(streamed.size(), a.events.size());
  EXPECT_EQ(0, std::memcmp(a.events.data(), streamed.data(), a.events.size() * sizeof(Event)));
}

// ---------------------------------------------------------------------------
// The metric: an oracle scores perfectly, known perturbations score as such.
// ---------------------------------------------------------------------------

std::vector<AugmentedEvent> oracle(const SyntheticScene& scene, double lifetime_scale, double rotate_deg) {
  std::vector<AugmentedEvent> out(scene.events.size());
  const double c = std::cos(rotate_deg * kPi / 180.0), s = std::sin(rotate_deg * kPi / 180.0);
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i].event = scene.events[i];
    const EventTruth& t = scene.truth[i];
    if (t.is_noise) continue;
    const double tau = t.lifetime_us * lifetime_scale;
    const double nx = c * t.nx - s * t.ny, ny = s * t.nx + c * t.ny;
    out[i].lifetime_us = static_cast<float>(tau);
    out[i].vx_px_s = static_cast<float>(nx / tau * 1e6);
    out[i].vy_px_s = static_cast<float>(ny / tau * 1e6);
  }
  return out;
}

TEST(AccuracyMetrics, OracleAndKnownPerturbations) {
  const SyntheticScene scene = evlife::io::generate_scene(evlife::io::edges_scene({120, 90}, 300'000, 5));
  {
    const auto r = evlife::test::evaluate_accuracy(scene, oracle(scene, 1.0, 0.0));
    EXPECT_GT(r.overall.edge_events, 10000u);
    EXPECT_GT(r.overall.noise_events, 1000u);
    EXPECT_EQ(r.overall.lifetime_share, 1.0);
    EXPECT_LT(r.overall.p90_rel_error, 1e-6);
    EXPECT_LT(r.overall.median_dir_error_deg, 0.05);
    EXPECT_EQ(r.overall.noise_share, 1.0);
  }
  {
    const auto r = evlife::test::evaluate_accuracy(scene, oracle(scene, 1.05, 10.0));
    EXPECT_NEAR(r.overall.median_rel_error, 0.05, 1e-4);
    EXPECT_NEAR(r.overall.median_signed_rel_error, 0.05, 1e-4);
    EXPECT_NEAR(r.overall.median_dir_error_deg, 10.0, 0.05);
    EXPECT_EQ(r.overall.share_within_30_percent, 1.0);
    EXPECT_EQ(r.overall.share_off_by_over_100_percent, 0.0);
  }
  {  // lifetimes 2.5 times too long: none within 30 %, all more than 100 % off
    const auto r = evlife::test::evaluate_accuracy(scene, oracle(scene, 2.5, 0.0));
    EXPECT_EQ(r.overall.share_within_30_percent, 0.0);
    EXPECT_EQ(r.overall.share_off_by_over_100_percent, 1.0);
  }
  {  // everything labelled noise / everything given a lifetime
    std::vector<AugmentedEvent> none = oracle(scene, 1.0, 0.0);
    for (auto& a : none) a.lifetime_us = 0.0f;
    EXPECT_EQ(evlife::test::evaluate_accuracy(scene, none).overall.lifetime_share, 0.0);
    std::vector<AugmentedEvent> all = oracle(scene, 1.0, 0.0);
    for (auto& a : all) a.lifetime_us = std::max(a.lifetime_us, 1000.0f);
    EXPECT_EQ(evlife::test::evaluate_accuracy(scene, all).overall.noise_share, 0.0);
  }
}

// accuracy_sweep --why: each event's outcome read from the estimator's
// counters. On DVS-pixel edges the followers inherit their burst's estimate,
// the first events fit their own plane, background activity mostly finds no
// plane; each row's outcomes add up to its events.
TEST(RejectionBreakdown, OutcomesByKindOfEvent) {
  SceneSpec spec = evlife::io::edges_scene({120, 90}, 400'000, 5);
  ASSERT_TRUE(evlife::io::apply_pixel_setting(spec, "dvs"));
  spec.noise_rate_hz_per_px = 2.0;  // enough background events to score
  const SyntheticScene scene = evlife::io::generate_scene(spec);
  const auto rows = evlife::test::rejection_breakdown(scene, evlife::LifetimeOptions{});
  ASSERT_EQ(rows.size(), 5u);
  std::cout << evlife::test::format_breakdown("edges 120x90, dvs pixels", rows);
  using evlife::test::Outcome;
  const auto share = [&](std::size_t row, Outcome o) {
    return static_cast<double>(rows[row].outcomes[static_cast<std::size_t>(o)]) / static_cast<double>(rows[row].events);
  };
  for (const auto& r : rows) {
    std::size_t sum = 0;
    for (const std::size_t n : r.outcomes) sum += n;
    EXPECT_EQ(sum, r.events) << r.kind;
  }
  ASSERT_GT(rows[0].events, 5000u);  // first events on a plane
  ASSERT_GT(rows[2].events, 2000u);  // followers
  ASSERT_GT(rows[3].events, 500u);   // background activity
  EXPECT_GT(share(0, Outcome::lifetime), 0.9);
  EXPECT_GT(share(2, Outcome::follower), 0.6);
  EXPECT_LT(share(2, Outcome::lifetime), 0.3);
  // Every background event counts here, also those within an edge's burst
  // window at their pixel (indistinguishable from followers: 5.6 % follow).
  EXPECT_LT(share(3, Outcome::lifetime) + share(3, Outcome::follower), 0.10);
  EXPECT_GT(share(3, Outcome::few_samples) + share(3, Outcome::unsupported), 0.88);
}

// ---------------------------------------------------------------------------
// The estimator against the issue's floors, default options.
// ---------------------------------------------------------------------------

evlife::test::AccuracyReport run_estimator(const SyntheticScene& scene, evlife::LifetimeOptions options) {
  options.sensor = scene.spec.sensor;
  evlife::LifetimeEstimator estimator(options);
  std::vector<AugmentedEvent> out(scene.events.size());
  EXPECT_EQ(estimator.process(scene.events, out), out.size());
  evlife::test::AccuracyOptions metric;
  metric.window_size = options.window_size;
  return evlife::test::evaluate_accuracy(scene, out, metric);
}

void expect_floors(std::size_t index) {
  const evlife::test::AccuracyScene scene_def = evlife::test::ideal_accuracy_scenes()[index];
  const std::string& title = scene_def.title;
  const SceneSpec& spec = scene_def.spec;
  const SyntheticScene scene = evlife::io::generate_scene(spec);
  const auto report = run_estimator(scene, evlife::LifetimeOptions{});  // defaults but the sensor
  std::cout << evlife::test::format_accuracy_table(
      title + " (" + std::to_string(scene.events.size()) + " events)", report);

  const auto& o = report.overall;
  ASSERT_GT(o.edge_events, 20000u);
  ASSERT_GT(o.noise_events, 1000u);
  EXPECT_GE(o.lifetime_share, 0.95) << title;
  EXPECT_LE(o.median_rel_error, 0.02) << title;
  EXPECT_LE(o.p90_rel_error, 0.10) << title;
  EXPECT_LE(o.median_dir_error_deg, 3.0) << title;
  EXPECT_GE(o.noise_share, 0.97) << title;
}

// Indices into evlife::test::ideal_accuracy_scenes().
TEST(LifetimeAccuracy, EdgesDavis240) { expect_floors(0); }
TEST(LifetimeAccuracy, EdgesDavis346) { expect_floors(1); }
TEST(LifetimeAccuracy, RotatingBarDavis240) { expect_floors(2); }
TEST(LifetimeAccuracy, RotatingBarDavis346) { expect_floors(3); }
TEST(LifetimeAccuracy, MixedDvs128) { expect_floors(4); }

// ---- Realistic pixels (issue 11): bursts, threshold mismatch, latency
// jitter, refractory period, background activity, hot pixels ----

struct PixelFloors {
  double lifetime_share, median_rel_error, p90_rel_error, median_dir_error_deg, noise_share;
};
constexpr PixelFloors kNormalLightFloors{0.95, 0.05, 0.15, 3.0, 0.97};
// Issue 11's dim-light floors: 0.85 / 10 % / 30 % / 5 deg / 97 %.
constexpr PixelFloors kIssueDimLightFloors{0.85, 0.10, 0.30, 5.0, 0.97};
// No floor: for the variant a test compares against.
constexpr PixelFloors kNoFloors{0.0, 1.0, 100.0, 90.0, 0.0};

// Indices into evlife::test::pixel_model_accuracy_scenes().
enum PixelScene : std::size_t { kEdgesNormal, kBarNormal, kEdgesDim, kBarDim };

// The scene of `index` with `sensor` applied (it changes the scene's pixel
// model; none: the setting as it is), and its title.
std::pair<SyntheticScene, std::string> pixel_scene(PixelScene index, const std::function<void(SceneSpec&)>& sensor) {
  evlife::test::AccuracyScene scene_def = evlife::test::pixel_model_accuracy_scenes()[index];
  if (sensor) sensor(scene_def.spec);
  return {evlife::io::generate_scene(scene_def.spec), scene_def.title};
}

// The floors on a generated scene; `title` names it in the table and failures.
evlife::test::AccuracyReport expect_pixel_floors(const SyntheticScene& scene, const std::string& title,
                                                 const PixelFloors& floors, const evlife::LifetimeOptions& options) {
  const auto report = run_estimator(scene, options);
  std::cout << evlife::test::format_accuracy_table(title + " (" + std::to_string(scene.events.size()) + " events)",
                                                   report);
  const auto& o = report.overall;
  EXPECT_GT(o.edge_events, 20000u);
  EXPECT_GT(o.noise_events, 500u);
  EXPECT_GE(o.lifetime_share, floors.lifetime_share) << title;
  EXPECT_LE(o.median_rel_error, floors.median_rel_error) << title;
  EXPECT_LE(o.p90_rel_error, floors.p90_rel_error) << title;
  EXPECT_LE(o.median_dir_error_deg, floors.median_dir_error_deg) << title;
  EXPECT_GE(o.noise_share, floors.noise_share) << title;
  return report;
}

// `variant`: appended to the scene's title, e.g. ", dim-light preset".
evlife::test::AccuracyReport expect_pixel_floors(PixelScene index, const std::string& variant,
                                                 const PixelFloors& floors, const evlife::LifetimeOptions& options = {},
                                                 const std::function<void(SceneSpec&)>& sensor = {}) {
  const auto [scene, title] = pixel_scene(index, sensor);
  return expect_pixel_floors(scene, title + variant, floors, options);
}

TEST(PixelModelAccuracy, EdgesDavis346NormalLight) { expect_pixel_floors(kEdgesNormal, "", kNormalLightFloors); }
TEST(PixelModelAccuracy, RotatingBarDavis346NormalLight) {
  expect_pixel_floors(kBarNormal, "", kNormalLightFloors);
}
TEST(PixelModelAccuracy, EdgesDavis346DimLight) { expect_pixel_floors(kEdgesDim, "", kIssueDimLightFloors); }
TEST(PixelModelAccuracy, RotatingBarDavis346DimLight) { expect_pixel_floors(kBarDim, "", kIssueDimLightFloors); }

// Issue 11's dim-light floors, all met with config/dim-light.yaml (lifetimes
// at least two standard errors from zero).
using evlife::test::dim_light_preset;

TEST(PixelModelAccuracy, EdgesDavis346DimLightWithDimLightPreset) {
  expect_pixel_floors(kEdgesDim, ", dim-light preset", kIssueDimLightFloors, dim_light_preset());
}

TEST(PixelModelAccuracy, RotatingBarDavis346DimLightWithDimLightPreset) {
  expect_pixel_floors(kBarDim, ", dim-light preset", kIssueDimLightFloors, dim_light_preset());
}

// The preset in normal light still meets the normal-light floors.
TEST(PixelModelAccuracy, EdgesDavis346NormalLightWithDimLightPreset) {
  expect_pixel_floors(kEdgesNormal, ", dim-light preset", kNormalLightFloors, dim_light_preset());
}

// A harder sensor at the edges of the issue's ranges: threshold mismatch
// sigma 0.04 log units, refractory period 1 ms, background activity 2 Hz/px
// (twice the top of room temperature), ten times the hot pixels, at 50 Hz.
// Each within what DVS128 / DAVIS papers and v2e report; the floors must hold
// for such a camera too (`accuracy_sweep --pixel threshold-sigma=0.04 --pixel
// refractory-us=1000 --pixel hot-pixels=0.001 --pixel hot-rate=50 --noise-rate 2`).
void harder_sensor(SceneSpec& spec) {
  spec.pixel.threshold_mismatch_sigma = 0.04;
  spec.pixel.refractory_us = 1000.0;
  spec.pixel.hot_pixel_fraction = 1e-3;
  spec.pixel.hot_pixel_rate_hz = 50.0;
  spec.noise_rate_hz_per_px = 2.0;
}

TEST(PixelModelAccuracy, EdgesDavis346NormalLightHarderSensor) {
  expect_pixel_floors(kEdgesNormal, ", harder sensor", kNormalLightFloors, {}, harder_sensor);
}

TEST(PixelModelAccuracy, EdgesDavis346DimLightHarderSensor) {
  expect_pixel_floors(kEdgesDim, ", harder sensor", kIssueDimLightFloors, {}, harder_sensor);
}

// Hot pixels as real DVXplorers have them, far past the settings' 1e-4 at
// 20 Hz: sample.aedat4 has pixels firing at 0.9-1.1 kHz all through it, and
// the static scene of rosbag/test_data_libcaer_rollover has 1.1e-3 of its
// pixels at 10 Hz or more, 2.3e-4 at 100 Hz, 1.6e-5 at 1 kHz (README, *Real
// background activity*). Here 1e-3 of the pixels at 1 kHz. Within a burst's
// span such a pixel fires dozens of events, which passed as the followers of
// an edge's burst there; max_burst_followers (16) judges the rest on their
// own. Measured: noise labelled noise 95.78 -> 97.13 % (normal light),
// 96.84 -> 97.43 % (dim); on the seeds +100 and +200 (`accuracy_sweep
// --seed-offset`) +0.8 to +1.5 points, but the dim edges of +100 at 96.65 %:
// at this density the issue's 97 % is not met on every seed. The edges'
// accuracy is unchanged.
TEST(PixelModelAccuracy, KilohertzHotPixelsDoNotPassAsBurstFollowers) {
  for (const PixelScene index : {kEdgesNormal, kEdgesDim}) {
    const auto [scene, title] = pixel_scene(index, [](SceneSpec& spec) {
      spec.pixel.hot_pixel_fraction = 1e-3;
      spec.pixel.hot_pixel_rate_hz = 1000.0;
    });
    evlife::LifetimeOptions unlimited;
    unlimited.max_burst_followers = 0;
    const auto limited_report = run_estimator(scene, evlife::LifetimeOptions{});
    const auto unlimited_report = run_estimator(scene, unlimited);
    std::cout << evlife::test::format_accuracy_table(title + ", 1e-3 of the pixels hot at 1 kHz", limited_report)
              << evlife::test::format_accuracy_table(title + ", the same, max_burst_followers 0", unlimited_report);
    const auto& with = limited_report.overall;
    const auto& without = unlimited_report.overall;
    EXPECT_GE(with.noise_share, without.noise_share + 0.005) << title;
    EXPECT_GE(with.noise_share, 0.97) << title;  // this seed's
    EXPECT_NEAR(with.lifetime_share, without.lifetime_share, 0.002) << title;
    EXPECT_NEAR(with.median_rel_error, without.median_rel_error, 0.002) << title;
  }
}

// Contrast 0.35 against threshold 0.3 (below).
void faint_texture(SceneSpec& spec) {
  spec.pixel.contrast_log = 0.35;
  spec.pixel.threshold_log = 0.3;
}

// Faint texture: contrast 0.35 against threshold 0.3 gives the burst
// statistics of the slider recording (1.07 events per burst, 93 % single
// events; algo/README.md, *Across the sensor range*). A pixel then fires anywhere
// within its edge's ramp (1.3 lifetimes wide), so the issue's normal-light
// floors are out of reach at N = 5; these floors are today's figures (share
// 94.7 %, median 8.1 %, p90 24.4 %, 3.7 deg, noise 96.9 %) less a margin: a
// change that helps the settings must not give up the regime real scenes
// are in.
TEST(PixelModelAccuracy, EdgesDavis346NormalLightFaintTexture) {
  constexpr PixelFloors kFaintTextureFloors{0.93, 0.09, 0.27, 4.2, 0.96};
  expect_pixel_floors(kEdgesNormal, ", faint texture", kFaintTextureFloors, {}, faint_texture);
}

// config/faint-texture.yaml.
using evlife::test::faint_texture_preset;

// The preset in faint texture: more share than the defaults (95.0 %) and the
// issue's noise floor, which the defaults miss there only just (96.93 %; 97.00 %
// before the ramp followers, 96.7 % before their offset check on continuations). The wide band alone, with no
// offset check, labels less noise noise (96.3 %): the check is what keeps it.
TEST(PixelModelAccuracy, FaintTexturePresetKeepsTheNoiseFloorInFaintTexture) {
  constexpr PixelFloors kPresetFloors{0.965, 0.09, 0.27, 4.2, 0.97};
  const auto [scene, title] = pixel_scene(kEdgesNormal, faint_texture);
  const auto with_check =
      expect_pixel_floors(scene, title + ", faint texture, faint-texture preset", kPresetFloors, faint_texture_preset());
  evlife::LifetimeOptions band_alone = faint_texture_preset();
  band_alone.max_event_offset_tolerances = 0.0;
  band_alone.continuation_max_event_offset_tolerances = 0.0;
  const auto without =
      expect_pixel_floors(scene, title + ", faint texture, wide band without the check", kNoFloors, band_alone);
  EXPECT_GE(with_check.overall.noise_share, without.overall.noise_share + 0.005);
}

// And it keeps the normal-light floors on the standard scenes.
TEST(PixelModelAccuracy, EdgesDavis346NormalLightWithFaintTexturePreset) {
  expect_pixel_floors(kEdgesNormal, ", faint-texture preset", kNormalLightFloors, faint_texture_preset());
}

TEST(PixelModelAccuracy, RotatingBarDavis346NormalLightWithFaintTexturePreset) {
  expect_pixel_floors(kBarNormal, ", faint-texture preset", kNormalLightFloors, faint_texture_preset());
}

// A continuation refits the upstream plane's inliers where that plane holds
// as many samples as RANSAC's best draw. On the rotating bar in dim light
// with 600 us of latency jitter (the issue's upper range) refitting the
// draw's inliers instead gave a share of 83.3 % (now 84.9 %; accuracy_sweep
// --pixel latency-jitter-us=600), measured without the continuations' offset
// check, which is held here off so that the test sees the upstream plane
// alone (with it, the default: 84.0 %). Only the share is held: at this
// jitter the bar misses the issue's p90 and direction floors either way
// (README, *Across the sensor range*).
TEST(PixelModelAccuracy, FastBarInDimLightContinuesTheUpstreamPlane) {
  constexpr PixelFloors kShareOnly{0.845, 1.0, 100.0, 90.0, 0.97};
  evlife::LifetimeOptions no_continuation_check;
  no_continuation_check.continuation_max_event_offset_tolerances = 0.0;
  expect_pixel_floors(kBarDim, ", 600 us jitter", kShareOnly, no_continuation_check,
                      [](SceneSpec& spec) { spec.pixel.latency_jitter_us = 600.0; });
}

// The dim-light edges with the clock started elsewhere: at Unix time in
// microseconds (~1.76e15, where a double steps by 0.25 us) and at the end of
// the time range (2^62: steps of 1024 us). The estimator reads differences of
// times only, so the figures stay those of the clock started at 0 (RANSAC's
// draws, seeded by t, differ: within 0.3 points). A continuation's prediction
// error was taken between absolute times in double: at 2^62, 2 points more of
// the edge events got a lifetime (from planes the tolerance should have refused).
TEST(PixelModelAccuracy, EstimatesDoNotDependOnWhereTheClockStarted) {
  const SyntheticScene scene = pixel_scene(kEdgesDim, {}).first;
  const auto from_zero = run_estimator(scene, {}).overall;
  for (const std::int64_t start_us : {std::int64_t{1'764'000'000'000'000}, evlife::kMaxEventTimeUs - (std::int64_t{1} << 32)}) {
    SyntheticScene shifted = scene;
    for (Event& e : shifted.events) e.t_us += start_us;
    const auto o = run_estimator(shifted, {}).overall;
    std::printf("clock started at %lld us: with a lifetime %.4f (from 0: %.4f), median error %.4f (%.4f), noise "
                "labelled noise %.4f (%.4f)\n",
                static_cast<long long>(start_us), o.lifetime_share, from_zero.lifetime_share, o.median_rel_error,
                from_zero.median_rel_error, o.noise_share, from_zero.noise_share);
    EXPECT_NEAR(o.lifetime_share, from_zero.lifetime_share, 0.006) << start_us;
    EXPECT_NEAR(o.median_rel_error, from_zero.median_rel_error, 0.003) << start_us;
    EXPECT_NEAR(o.noise_share, from_zero.noise_share, 0.006) << start_us;
  }
}

// A dim scene as v2e's `--dvs_params noisy` models it: threshold 0.2,
// mismatch 0.05, the photoreceptor at 30 Hz (T = 5.3 ms), shot noise 5 Hz
// (background activity 5 Hz/px here; its 0.1 Hz of leak events is left out),
// no refractory period, no latency jitter beyond the photoreceptor's. Edges faster than
// ~2 T are not resolved (below); without an offset check a tenth of the edge
// events get lifetimes over ten times too long (p90 1290 %) from steep planes
// through stale and noise samples, and 94.7 % of the noise is labelled noise. The
// dim-light preset's offset check rejects those planes (41.6 % with a
// lifetime, median 11.0 %, p90 41.1 %, 4.5 deg, 96.79 % of the noise labelled
// noise; 40.1 / 11.5 / 44.6 / 4.6 / 96.97 before the ramp followers): its floors
// here, less a margin.
void slow_noisy_pixel(SceneSpec& spec) {
  spec.pixel.cutoff_hz = 30.0;
  spec.pixel.threshold_mismatch_sigma = 0.05;
  spec.pixel.latency_us = spec.pixel.latency_jitter_us = spec.pixel.refractory_us = 0.0;
  spec.noise_rate_hz_per_px = 5.0;
}

// The defaults' offset check on continuations (1.8 lifetimes) removes most
// of the far-off lifetimes there: 50.0 % with a lifetime, median 13.6 %, p90
// 114 %, 5.7 deg, 95.7 % of the noise labelled noise (without it: 69.2 /
// 27.9 / 1290 / 12.1 / 94.7, measured before the ramp followers). Its floors here, less a margin; the p90 fails
// without the check.
TEST(PixelModelAccuracy, DefaultsGiveFewFarOffLifetimesOnASlowNoisyPixel) {
  constexpr PixelFloors kSlowNoisyDefaults{0.45, 0.17, 1.3, 7.0, 0.95};
  expect_pixel_floors(kEdgesNormal, ", 30 Hz photoreceptor, 5 Hz/px", kSlowNoisyDefaults, {}, slow_noisy_pixel);
}

// Soft edges: a luminance ramp 3 px wide (defocus, a soft shadow) passes a
// pixel in 3 lifetimes and the pixel fires every 3 theta / C of them, past
// the follower window: such events were taken for new arrivals, overwrote the
// arrival in the surface, and the fits downstream came out flat (median
// error 12.7 %, p90 47.9 %, lifetimes short). Followers while the ramp is
// seen passing upstream (ramp_follower_span_lifetimes) keep them: today 90.7 %
// with a lifetime, median 9.4 %, p90 32.7 %, noise 97.2 % (`accuracy_sweep
// --pixel edge-blur-px=3`); these floors less a margin, and the p90 fails
// without the rule.
TEST(PixelModelAccuracy, RampFollowersKeepASoftEdgesLifetimes) {
  constexpr PixelFloors kSoftEdges{0.88, 0.11, 0.38, 4.5, 0.965};
  const auto [scene, title] = pixel_scene(kEdgesNormal, [](SceneSpec& spec) { spec.pixel.edge_blur_px = 3.0; });
  const auto on = expect_pixel_floors(scene, title + ", 3 px ramps", kSoftEdges, {});
  evlife::LifetimeOptions no_ramp;
  no_ramp.ramp_follower_span_lifetimes = 0.0;
  const auto off = expect_pixel_floors(scene, title + ", 3 px ramps, no ramp followers", kNoFloors, no_ramp);
  EXPECT_LE(on.overall.p90_rel_error, off.overall.p90_rel_error - 0.08);
  EXPECT_GT(on.overall.median_signed_rel_error, off.overall.median_signed_rel_error);  // less short
}

TEST(PixelModelAccuracy, DimLightPresetGivesNoFarOffLifetimesOnASlowNoisyPixel) {
  constexpr PixelFloors kSlowNoisy{0.35, 0.13, 0.55, 5.5, 0.965};
  expect_pixel_floors(kEdgesNormal, ", 30 Hz photoreceptor, 5 Hz/px, dim-light preset", kSlowNoisy,
                      dim_light_preset(), slow_noisy_pixel);
}

// A photoreceptor of limited bandwidth (io::PixelModel::cutoff_hz; dim light
// 10-300 Hz) follows each edge with its time constant, T = 1 / (2 pi F) for ON
// edges and e^C T for OFF edges (to the dark side): the moment a pixel fires
// spreads over ~T / 2 whatever the edge's speed, so edges faster than about
// T are not resolved by any 5 x 5 window (algo/README.md, *A photoreceptor of
// limited bandwidth*). At 100 Hz (T = 1.6 ms, 2.6 ms for OFF edges) the bands
// from 5 ms up hold these floors (today 98.8-99.9 %, medians 4.9-6.8 %, p90
// 12.5-18.3 %, less a margin; `accuracy_sweep --pixel cutoff-hz=100 --bands`),
// so that no change gives up the edges such a sensor does resolve.
const evlife::test::AccuracyMetrics& band_row(const evlife::test::AccuracyReport& report, const std::string& label) {
  for (const auto& row : report.per_lifetime) {
    if (row.label == label) return row;
  }
  ADD_FAILURE() << "no band " << label;
  return report.overall;
}

TEST(PixelModelAccuracy, SlowPhotoreceptorResolvesEdgesSlowerThanItsTimeConstant) {
  constexpr PixelFloors kNoiseFloorOnly{0.0, 1.0, 100.0, 90.0, 0.97};
  const auto report = expect_pixel_floors(kEdgesNormal, ", 100 Hz photoreceptor", kNoiseFloorOnly, {},
                                          [](SceneSpec& spec) { spec.pixel.cutoff_hz = 100.0; });
  for (const char* band : {"lifetime 5000..10000 us", "lifetime 10000..20000 us"}) {
    const auto& row = band_row(report, band);
    EXPECT_GT(row.edge_events, 5000u) << band;
    EXPECT_GE(row.lifetime_share, 0.95) << band;
    EXPECT_LE(row.median_rel_error, 0.08) << band;
    EXPECT_LE(row.p90_rel_error, 0.22) << band;
  }
}

// The dim-light preset keeps each burst's arrival in the surface where a
// slow photoreceptor fires its later events a time constant or two after it
// (late_event_keeps_arrival_timing_noise, late_follower_upstream_durations):
// at 100 Hz (normal-light edges) its p90 error 28.2 -> 21.5 %, median 7.4 ->
// 6.7 %, share 74.9 -> 75.2 %, noise 97.98 -> 98.13 % (`accuracy_sweep
// --config config/dim-light.yaml --pixel cutoff-hz=100`). Its floors here,
// less a margin; the p90 fails without the two keys.
TEST(PixelModelAccuracy, DimLightPresetKeepsTheArrivalsOfASlowPhotoreceptor) {
  constexpr PixelFloors kSlowPhotoreceptor{0.73, 0.075, 0.245, 3.5, 0.975};
  const auto [scene, title] = pixel_scene(kEdgesNormal, [](SceneSpec& spec) { spec.pixel.cutoff_hz = 100.0; });
  const auto with = expect_pixel_floors(scene, title + ", 100 Hz photoreceptor, dim-light preset", kSlowPhotoreceptor,
                                        dim_light_preset());
  evlife::LifetimeOptions without = dim_light_preset();
  without.late_event_keeps_arrival_timing_noise = without.late_follower_upstream_durations = 0.0;
  const auto off = expect_pixel_floors(scene, title + ", 100 Hz photoreceptor, dim-light preset, arrivals overwritten",
                                       kNoFloors, without);
  EXPECT_LE(with.overall.p90_rel_error, off.overall.p90_rel_error - 0.04);
}

// At 30 Hz (v2e's 'noisy' photoreceptor, T = 5.3 ms) a burst's later events
// come several ms after its first, many lifetimes of a 2-5 ms edge: taken for
// new arrivals they overwrote the arrival in the surface, and the fits
// downstream came out short. estimator.burst_span_timing_noise keeps them
// followers while no newer edge has come from upstream: the band's bias
// shrinks (see config/evlife.yaml for why it is not on by default).
TEST(PixelModelAccuracy, SlowPhotoreceptorFollowersKeepTheirBurstsArrival) {
  const auto [scene, title] = pixel_scene(kEdgesNormal, [](SceneSpec& spec) { spec.pixel.cutoff_hz = 30.0; });
  const auto off = expect_pixel_floors(scene, title + ", 30 Hz photoreceptor", kNoFloors, {});
  evlife::LifetimeOptions late;
  late.burst_span_timing_noise = 10.0;
  const auto on = expect_pixel_floors(scene, title + ", 30 Hz photoreceptor, late followers", kNoFloors, late);
  const auto& before = band_row(off, "lifetime 2000..5000 us");
  const auto& after = band_row(on, "lifetime 2000..5000 us");
  std::cout << "2-5 ms band, median signed error: " << before.median_signed_rel_error << " -> "
            << after.median_signed_rel_error << "\n";
  EXPECT_LT(before.median_signed_rel_error, -0.10);  // the bias the surface's overwritten arrivals cause
  EXPECT_GE(after.median_signed_rel_error, before.median_signed_rel_error + 0.03);
  EXPECT_LT(after.median_rel_error, before.median_rel_error);
}

// Beyond the floors: where does the estimator stop working? Not a pass/fail
// test; run with --gtest_also_run_disabled_tests --gtest_filter=*Sweep* to
// print one row per condition (faster edges, more noise, more jitter, dense
// patterns).
TEST(LifetimeAccuracy, DISABLED_StressSweep) {
  auto grating = [](double dir, double tau, double period, double width) {
    evlife::io::GratingSpec g;
    g.direction_deg = dir;
    g.lifetime_us = tau;
    g.period_px = period;
    g.bar_width_px = width;
    return g;
  };
  struct Case {
    std::string name;
    SceneSpec spec;
    evlife::LifetimeOptions options{};  // the defaults unless a case varies them
  };
  std::vector<Case> cases;
  for (double tau : {50.0, 100.0, 150.0, 200.0, 300.0, 30000.0, 50000.0}) {
    SceneSpec s;
    s.sensor = {120, 90};
    s.gratings = {grating(37.0, tau, tau < 1000 ? 30.0 : 8.0, tau < 1000 ? 15.0 : 4.0)};
    s.duration_us = std::max<std::int64_t>(60'000, static_cast<std::int64_t>(8 * s.gratings[0].period_px * tau));
    cases.push_back({"grating 37 deg, lifetime " + std::to_string(static_cast<int>(tau)) + " us", s});
  }
  for (double rate : {3.0, 10.0, 30.0}) {
    SceneSpec s = evlife::io::edges_scene({240, 180}, 600'000, 9);
    s.noise_rate_hz_per_px = rate;
    cases.push_back({"edges, noise " + std::to_string(static_cast<int>(rate)) + " Hz/px", s});
  }
  for (double jitter : {50.0, 100.0}) {
    SceneSpec s = evlife::io::edges_scene({240, 180}, 600'000, 9);
    s.jitter_sigma_us = jitter;
    cases.push_back({"edges, jitter " + std::to_string(static_cast<int>(jitter)) + " us", s});
  }
  for (double period : {6.0, 8.0}) {
    SceneSpec s;
    s.sensor = {120, 90};
    s.gratings = {grating(121.0, 2000.0, period, 2.0)};
    s.duration_us = 400'000;
    cases.push_back({"dense grating, period " + std::to_string(static_cast<int>(period)) + " px", s});
  }
  {
    SceneSpec s = evlife::io::rotating_bar_scene({240, 180}, 300'000, 9);
    s.bars[0].omega_start_deg_s = 1200.0;
    s.bars[0].omega_end_deg_s = 3000.0;
    cases.push_back({"bar 1200->3000 deg/s in 0.3 s", s});
  }
  // The regularization weight (README, estimator parameters): the default
  // 0.1 against 1.0 (the prior then outweighs a 5 x 5 window's data) and off.
  for (double unit : {0.0, 0.1, 1.0}) {
    Case c{"bar 150->1200 deg/s, lambda_unit " + std::to_string(unit).substr(0, 3),
           evlife::io::rotating_bar_scene({240, 180}, 1'000'000, 7)};
    c.options.lambda_unit_px2 = unit;
    cases.push_back(c);
  }
  std::printf("%-36s %8s %7s %8s %8s %8s %7s %8s\n", "condition", "edges", "w/ tau%", "med rel%",
              "p90 rel%", "bias%", "med dir", "noise%");
  for (const auto& c : cases) {
    const SyntheticScene scene = evlife::io::generate_scene(c.spec);
    const auto o = run_estimator(scene, c.options).overall;
    std::printf("%-36s %8zu %7.2f %8.2f %8.2f %+8.2f %7.2f %8.2f\n", c.name.c_str(), o.edge_events,
                100.0 * o.lifetime_share, 100.0 * o.median_rel_error, 100.0 * o.p90_rel_error,
                100.0 * o.median_signed_rel_error, o.median_dir_error_deg, 100.0 * o.noise_share);
  }
}

}  // namespace

// ---- A natural texture through the same pixels (textured_scene.h: dead
// leaves, edges of every contrast, orientation and curvature, occlusions) ----
// No issue floor: regression floors a few points under today's figures
// (README, *What it reaches*). Scored: edge events where the texture's
// iso-line is straight over the window; the share of all events with a
// lifetime (as on a recording: curved edges, junctions, onsets included) is
// printed and floored too.
void expect_textured_floors(std::size_t index, const PixelFloors& floors, double all_events_share) {
  const evlife::test::AccuracyScene s = evlife::test::textured_accuracy_scenes()[index];
  const SyntheticScene scene = s.generate();
  const auto report = run_estimator(scene, evlife::LifetimeOptions{});
  std::cout << evlife::test::format_accuracy_table(s.title + " (" + std::to_string(scene.events.size()) + " events)",
                                                   report);
  const auto& o = report.overall;
  EXPECT_GT(o.edge_events, 20000u);
  EXPECT_GT(o.noise_events, 500u);
  EXPECT_GE(o.lifetime_share, floors.lifetime_share) << s.title;
  EXPECT_LE(o.median_rel_error, floors.median_rel_error) << s.title;
  EXPECT_LE(o.p90_rel_error, floors.p90_rel_error) << s.title;
  EXPECT_LE(o.median_dir_error_deg, floors.median_dir_error_deg) << s.title;
  EXPECT_GE(o.noise_share, floors.noise_share) << s.title;
  std::cout << "  share of all events with a lifetime (after the warm-up): " << o.all_events_lifetime_share << "\n";
  EXPECT_GE(o.all_events_lifetime_share, all_events_share) << s.title;
}

// The texture's truth checked against the events themselves: on large
// leaves (radii 30-40 px: straight at the window's scale) and near-ideal
// pixels (no latency, jitter, refractory period, mismatch or background;
// threshold 0.05), the estimator's lifetimes and directions must agree with
// the truth. A wrong truth (the lifetime from the tile's speed instead of the
// iso-line's normal speed, a flipped normal) fails this. Not zero:
// the first event of each crossing fires on the blurred step's tail, anywhere
// in its first 0.05 / C (measured: median 6.2 %, p90 27 %, 3.1 deg).
TEST(TexturedAccuracy, TruthAgreesWithTheEventsOnStraightLeaves) {
  evlife::io::TexturedSceneSpec spec = *evlife::test::textured_accuracy_scenes()[0].textured;
  spec.leaf_radius_min_px = 30.0;
  spec.leaf_radius_max_px = 40.0;
  evlife::test::make_pixels_near_ideal(spec);
  spec.pixel.threshold_log = 0.05;
  const SyntheticScene scene = evlife::io::generate_textured_scene(spec);
  const auto report = run_estimator(scene, evlife::LifetimeOptions{});
  std::cout << evlife::test::format_accuracy_table("dead leaves, radii 30-40 px, near-ideal pixels", report);
  const auto& o = report.overall;
  EXPECT_GT(o.edge_events, 20000u);
  EXPECT_GE(o.lifetime_share, 0.95);
  // (The lifetime from the tile's speed: median 10.3 %, bias +6.2 %; a
  // flipped normal: 177 deg.)
  EXPECT_LE(o.median_rel_error, 0.08);
  EXPECT_LE(std::fabs(o.median_signed_rel_error), 0.05);
  EXPECT_LE(o.median_dir_error_deg, 5.0);
}

TEST(TexturedAccuracy, DeadLeavesDavis346NormalLight) {
  expect_textured_floors(0, {0.86, 0.13, 0.42, 10.0, 0.97}, 0.65);
}
TEST(TexturedAccuracy, DeadLeavesDavis346DimLight) {
  expect_textured_floors(1, {0.80, 0.13, 0.42, 10.0, 0.97}, 0.52);
}

// Regularization (paper eq. 12-13) must help where real pixels make the plane
// data noisy: the same scenes with the prior ignored (regularization off) get
// worse lifetimes and directions. Fails if the prior is not used.
TEST(PixelModelAccuracy, RegularizationImprovesEstimatesOnRealisticPixels) {
  for (const PixelScene index : {kEdgesNormal, kBarNormal}) {
    const evlife::test::AccuracyScene scene_def = evlife::test::pixel_model_accuracy_scenes()[index];
    const std::string& title = scene_def.title;
    const SceneSpec& spec = scene_def.spec;
    const SyntheticScene scene = evlife::io::generate_scene(spec);
    evlife::LifetimeOptions off;
    off.regularization = false;
    const auto with = run_estimator(scene, evlife::LifetimeOptions{}).overall;
    const auto without = run_estimator(scene, off).overall;
    std::cout << title << ": median / p90 lifetime error, median direction error: regularized "
              << with.median_rel_error << " / " << with.p90_rel_error << " / " << with.median_dir_error_deg
              << " deg, not regularized " << without.median_rel_error << " / " << without.p90_rel_error << " / "
              << without.median_dir_error_deg << " deg\n";
    // Measured: 4.1 vs 6.9 % and 3.8 vs 8.6 % median error: the margin is wide.
    EXPECT_LT(with.median_rel_error, 0.8 * without.median_rel_error) << title;
    EXPECT_LT(with.p90_rel_error, 0.8 * without.p90_rel_error) << title;
    EXPECT_LT(with.median_dir_error_deg, without.median_dir_error_deg) << title;
  }
}
