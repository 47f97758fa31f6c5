// The estimator on the paper's real DVS128 recordings (../shared/data/reference),
// with the default options: the quantities of paper Figs. 9 and 10.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "evlife/algo/lifetime_estimator.h"
#include "evlife/io/event_reader.h"

namespace evlife {
namespace {

std::vector<AugmentedEvent> run_default(const std::string& name, LifetimeOptions o = {}) {
  const std::string path = std::string(EVLIFE_SHARED_DATA_DIR) + "/reference/" + name;
  if (!std::filesystem::exists(path)) return {};
  auto reader = io::open_event_reader(path);
  o.sensor = reader->sensor_size().value_or(SensorSize{128, 128});
  LifetimeEstimator est(o);
  std::vector<Event> in(8192);
  std::vector<AugmentedEvent> out;
  while (const std::size_t n = reader->read(in)) {
    const std::size_t base = out.size();
    out.resize(base + n);
    est.process(std::span<const Event>(in.data(), n), std::span<AugmentedEvent>(out).subspan(base));
  }
  return out;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// Paper Fig. 9: with N = 5, more than 90 % of predictions err by less than 10 ms.
TEST(RealRecordings, StripesPredictionErrorsMostlyBelow10ms) {
  const auto out = run_default("stripes.mat");
  if (out.empty()) GTEST_SKIP() << "shared data not found at " << EVLIFE_SHARED_DATA_DIR;
  ASSERT_EQ(out.size(), 340394u);
  std::size_t predictions = 0, below_10ms = 0;
  for (const auto& a : out) {
    if (!a.has_prediction()) continue;
    ++predictions;
    below_10ms += std::fabs(a.prediction_error_us) < 10000.0f;
  }
  EXPECT_GT(predictions, out.size() / 10);
  EXPECT_GT(static_cast<double>(below_10ms) / static_cast<double>(predictions), 0.90);
}

// Pure translation: lifetime grows with depth. The far board (0.2 m, rows
// 32-67) must get lifetimes at least 1.5x those of the near one (0.1 m, rows
// 72-127): the two peaks of paper Fig. 10.
TEST(RealRecordings, StripesFarPatternLivesLongerThanNearPattern) {
  for (bool regularization : {true, false}) {
    LifetimeOptions o;
    o.regularization = regularization;
    const auto out = run_default("stripes.mat", o);
    if (out.empty()) GTEST_SKIP() << "shared data not found";
    std::vector<double> far, near;
    for (const auto& a : out) {
      if (a.is_noise()) continue;
      if (a.event.y >= 32 && a.event.y <= 67) far.push_back(static_cast<double>(a.lifetime_us));
      if (a.event.y >= 72 && a.event.y <= 127) near.push_back(static_cast<double>(a.lifetime_us));
    }
    ASSERT_GT(far.size(), 1000u);
    ASSERT_GT(near.size(), 1000u);
    const double ratio = median(far) / median(near);
    EXPECT_GE(ratio, 1.5) << "regularization " << regularization << ": far " << median(far)
                          << " us, near " << median(near) << " us";
  }
}

// Garfield moves at one depth, horizontally: velocities are mostly horizontal
// and lifetimes of one scale (paper Fig. 11).
TEST(RealRecordings, GarfieldMotionIsHorizontalAndCoherent) {
  const auto out = run_default("garfield.mat");
  if (out.empty()) GTEST_SKIP() << "shared data not found";
  ASSERT_EQ(out.size(), 202235u);
  std::size_t edges = 0, horizontal = 0;
  std::vector<double> vx;
  for (const auto& a : out) {
    if (a.is_noise()) continue;
    ++edges;
    horizontal += std::fabs(a.vx_px_s) > 2.0f * std::fabs(a.vy_px_s);
    vx.push_back(static_cast<double>(a.vx_px_s));
  }
  EXPECT_GT(edges, out.size() / 5);
  EXPECT_GT(static_cast<double>(horizontal) / static_cast<double>(edges), 0.6);
  // One direction of travel: most horizontal velocities share the median's sign.
  const double m = median(vx);
  const auto same_sign = std::count_if(vx.begin(), vx.end(), [m](double v) { return v * m > 0; });
  EXPECT_GT(static_cast<double>(same_sign) / static_cast<double>(vx.size()), 0.8);
}

}  // namespace
}  // namespace evlife
