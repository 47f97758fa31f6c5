// The newer-half selection of the estimator's window (algo/src/window_samples.h):
// both algorithms must keep exactly the samples a plain stable sort keeps.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <numeric>
#include <random>
#include <vector>

#include "plane_fit.h"
#include "window_samples.h"

namespace evlife::detail {
namespace {

struct Sample {
  float dx, dy, dt;
  bool operator==(const Sample&) const = default;
};

std::vector<Sample> reference_keep(const std::vector<Sample>& in, int keep) {
  std::vector<int> order(in.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return in[a].dt > in[b].dt; });
  order.resize(std::min<std::size_t>(order.size(), static_cast<std::size_t>(keep)));
  std::sort(order.begin(), order.end());  // back to gather order
  std::vector<Sample> out;
  for (int i : order) out.push_back(in[i]);
  return out;
}

std::vector<Sample> kept(const WindowSamples& w) {
  std::vector<Sample> out;
  for (int k = 0; k < w.count; ++k) out.push_back({w.dx[k], w.dy[k], w.dt_us[k]});
  return out;
}

TEST(WindowSamples, BothSelectionsKeepTheNewestInGatherOrder) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 2000; ++trial) {
    const int count = 1 + static_cast<int>(rng() % kMaxNeighbours);
    const int keep = 1 + static_cast<int>(rng() % static_cast<unsigned>(count));
    std::vector<Sample> in;
    for (int k = 0; k < count; ++k) {
      // Few distinct times, so that ties are common. (k / 15: the row, on purpose.)
      // NOLINTNEXTLINE(bugprone-integer-division)
      in.push_back({static_cast<float>(k % 15), static_cast<float>(k / 15),
                    -static_cast<float>(rng() % 20) * 100.0f});
    }
    WindowSamples a, b;
    for (const Sample& s : in) {
      a.dx[a.count] = b.dx[b.count] = s.dx;
      a.dy[a.count] = b.dy[b.count] = s.dy;
      a.dt_us[a.count] = b.dt_us[b.count] = s.dt;
      ++a.count;
      ++b.count;
    }
    a.keep_newest_by_rank(keep);
    b.keep_newest_by_selection(keep);
    const auto expected = reference_keep(in, keep);
    ASSERT_EQ(kept(a), expected) << "rank, count " << count << " keep " << keep;
    ASSERT_EQ(kept(b), expected) << "selection, count " << count << " keep " << keep;
  }
}

TEST(WindowSamples, SupportCountsSamplesWithinTolerance) {
  WindowSamples w;
  const float dts[] = {-100.0f, -205.0f, -300.0f, -500.0f, -99.0f};
  for (int k = 0; k < 5; ++k) {
    w.dx[k] = -1.0f;
    w.dy[k] = 0.0f;
    w.dt_us[k] = dts[k];
  }
  w.count = 5;
  w.pad();
  // Plane dt = 100 * dx: expects -100 at dx = -1; within 10 us: -100, -99.
  EXPECT_EQ(w.support(100.0f, 0.0f, 10.0f * 10.0f), 2);
  EXPECT_EQ(w.support(100.0f, 0.0f, 110.0f * 110.0f), 3);
  EXPECT_EQ(w.support(100.0f, 0.0f, 1000.0f * 1000.0f), 5);  // padding never counts
}

// PlaneFit::add_inliers() (four samples at a time when the sums are exact)
// must give the refit the same sums bit for bit as add_if() sample by
// sample, with small and large (> 2^21 us: the scalar path) time offsets.
TEST(WindowSamples, RefitInliersSumLikeSampleBySample) {
  std::mt19937 rng(7);
  int fast = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    WindowSamples w;
    w.count = 1 + static_cast<int>(rng() % 24);
    const bool large = trial % 3 == 0;
    for (int k = 0; k < w.count; ++k) {
      w.dx[k] = static_cast<float>(static_cast<int>(rng() % 5) - 2);
      w.dy[k] = static_cast<float>(static_cast<int>(rng() % 5) - 2);
      const auto age = static_cast<std::int64_t>(rng() % (large && k % 2 == 0 ? 2'000'000'000u : 3000u));
      w.dt_us[k] = static_cast<float>(-age);
    }
    w.pad();
    const float gx = static_cast<float>(static_cast<int>(rng() % 400) - 200);
    const float gy = static_cast<float>(static_cast<int>(rng() % 400) - 200);
    // Every other trial with large offsets takes them all as inliers.
    const float tol2 = large && trial % 2 == 0 ? 1e30f : static_cast<float>(rng() % 300) * static_cast<float>(rng() % 300);
    PlaneFit a, b;
    a.add(0.0, 0.0, 0.0);
    b.add(0.0, 0.0, 0.0);
    a.add_inliers(w, gx, gy, tol2);
    for (int k = 0; k < w.count; ++k) {
      const float r = w.dt_us[k] - gx * w.dx[k] - gy * w.dy[k];
      b.add_if(r * r <= tol2, static_cast<double>(w.dx[k]), static_cast<double>(w.dy[k]), static_cast<double>(w.dt_us[k]));
    }
    Eigen::Vector2d ga = Eigen::Vector2d::Zero(), gb = Eigen::Vector2d::Zero();
    const Eigen::Vector2d prior(3.0, -4.0);
    const double lambda = trial % 2 == 0 ? 0.0 : 2.5;
    ASSERT_EQ(a.solve(lambda, prior, ga), b.solve(lambda, prior, gb)) << "trial " << trial;
    ASSERT_EQ(ga, gb) << "trial " << trial;
    const Eigen::Vector2d probe(17.0, -9.0);  // every sum enters the rms
    const double ra = a.residual_rms(probe), rb = b.residual_rms(probe);
    ASSERT_EQ(std::memcmp(&ra, &rb, sizeof ra), 0) << "trial " << trial << ": " << ra << " vs " << rb;
    fast += !large;
  }
  EXPECT_GT(fast, 1000);
}

}  // namespace
}  // namespace evlife::detail
