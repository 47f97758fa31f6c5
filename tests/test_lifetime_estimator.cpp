// Unit tests of the estimator on exact scenes whose answer is known
// analytically (a plane t = t0 + g.p sampled on the pixel grid).
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include "evlife/algo/lifetime_estimator.h"
#include "evlife/algo/make_lifetime_estimator.h"

namespace evlife {
namespace {

// Events of a straight edge moving along unit normal (cos a, sin a) at
// `speed_px_s`: pixel p fires when the edge line passes its centre, i.e. at
// t = t0 + (n . p) / speed. Sorted by time; exact (no jitter).
std::vector<Event> straight_edge(SensorSize s, double angle_rad, double speed_px_s,
                                 std::int8_t polarity = 1, std::int64_t t0_us = 1000) {
  std::vector<Event> ev;
  const double nx = std::cos(angle_rad), ny = std::sin(angle_rad);
  double min_proj = 1e300;
  for (int y = 0; y < s.height; ++y)
    for (int x = 0; x < s.width; ++x) min_proj = std::min(min_proj, nx * x + ny * y);
  for (int y = 0; y < s.height; ++y) {
    for (int x = 0; x < s.width; ++x) {
      const double t = t0_us + (nx * x + ny * y - min_proj) / speed_px_s * 1e6;
      ev.push_back({static_cast<std::int64_t>(std::llround(t)), static_cast<std::uint16_t>(x),
                    static_cast<std::uint16_t>(y), polarity});
    }
  }
  std::stable_sort(ev.begin(), ev.end(), [](const Event& a, const Event& b) { return a.t_us < b.t_us; });
  return ev;
}

LifetimeOptions options_for(SensorSize s) {
  LifetimeOptions o;
  o.sensor = s;
  return o;
}

bool interior(const Event& e, SensorSize s, int margin) {
  return e.x >= margin && e.y >= margin && e.x < s.width - margin && e.y < s.height - margin;
}

// evlife::algo tells the code built against it whether its constructors throw
// or abort (EVLIFE_ALGO_NO_EXCEPTIONS, an INTERFACE definition, installed with
// it); this test is built as the library is, so the two agree.
#if defined(__cpp_exceptions) == defined(EVLIFE_ALGO_NO_EXCEPTIONS)
#error "EVLIFE_ALGO_NO_EXCEPTIONS does not say how evlife::algo was built"
#endif

TEST(LifetimeOptions, DefaultsAreValid) { EXPECT_EQ(validate_lifetime_options({}), ""); }

// A value far outside an odd-only range is out of it, without casting it to
// an integer first (1e23 is no long long: undefined behaviour, which a
// constant expression refuses to compile, as UBSan reports it at run time).
TEST(LifetimeOptions, AnOddOnlyRangeRefusesAValueNoIntegerHolds) {
  constexpr evlife::OptionInfo odd{"window_size", "", 3.0, 15.0, false, false, true, false, "doc"};
  static_assert(!odd.contains(1e23) && !odd.contains(-1e23) && odd.contains(5.0) && !odd.contains(4.0));
  volatile double far = 1e23;  // and at run time
  EXPECT_FALSE(odd.contains(far));
}

TEST(LifetimeOptions, InvalidValuesNameTheField) {
  struct Case {
    void (*mutate)(LifetimeOptions&);
    const char* field;
  };
  const Case cases[] = {
      {[](LifetimeOptions& o) { o.window_size = 4; }, "window_size"},
      {[](LifetimeOptions& o) { o.window_size = 99; }, "window_size"},
      {[](LifetimeOptions& o) { o.sensor = {100000, 100000}; }, "sensor"},
      {[](LifetimeOptions& o) { o.sensor = {0, 10}; }, "sensor"},
      {[](LifetimeOptions& o) { o.outlier_fraction = 1.0; }, "outlier_fraction"},
      {[](LifetimeOptions& o) { o.ransac_confidence = 1.0; }, "ransac_confidence"},
      {[](LifetimeOptions& o) { o.inlier_tolerance_us = std::nan(""); }, "inlier_tolerance_us"},
      {[](LifetimeOptions& o) { o.inlier_tolerance_us = 0.0; }, "inlier_tolerance_us"},
      {[](LifetimeOptions& o) { o.lambda_gain = -1.0; }, "lambda"},
      {[](LifetimeOptions& o) { o.max_lifetime_us = 0.0; }, "max_lifetime_us"},
  };
  for (const Case& c : cases) {
    LifetimeOptions o;
    c.mutate(o);
    const std::string err = validate_lifetime_options(o);
    EXPECT_NE(err.find(c.field), std::string::npos) << err;
    const LifetimeEstimatorOrError made = make_lifetime_estimator(o);
    EXPECT_FALSE(made) << c.field;
    EXPECT_EQ(made.error, "LifetimeOptions." + err);
#if defined(__cpp_exceptions)
    try {
      LifetimeEstimator est(o);
      ADD_FAILURE() << "constructor accepted invalid " << c.field;
    } catch (const std::invalid_argument& ex) {
      EXPECT_NE(std::string(ex.what()).find(c.field), std::string::npos) << ex.what();
      EXPECT_EQ(made.error, ex.what());  // the factory says what the constructor says
    }
#else  // -fno-exceptions: the constructor cannot report, it stops the process
    // (a plain fork: gtest's death tests need the library built as the test is)
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      LifetimeEstimator est(o);
      _exit(0);  // accepted: the parent sees exit status 0
    }
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGABRT) << c.field;
#endif
  }
}

// Exact planes in several directions and speeds: interior events get the
// analytic lifetime 1/speed and velocity along the normal.
TEST(LifetimeEstimator, ExactPlaneGivesAnalyticLifetimeAndVelocity) {
  const SensorSize s{48, 36};
  for (double angle_deg : {0.0, 30.0, 90.0, 135.0, 200.0, 290.0}) {
    for (double speed : {200.0, 2000.0, 20000.0}) {
      for (bool reg : {false, true}) {
        LifetimeOptions o = options_for(s);
        o.regularization = reg;
        LifetimeEstimator est(o);
        const double a = angle_deg * std::numbers::pi / 180.0;
        const auto events = straight_edge(s, a, speed);
        int checked = 0, good = 0;
        for (std::size_t i = 0; i < events.size(); ++i) {
          const AugmentedEvent out = est.process(events[i]);
          if (i < events.size() / 4 || !interior(events[i], s, 3)) continue;
          ++checked;
          const double tau_true = 1e6 / speed;
          const double vx = static_cast<double>(out.vx_px_s), vy = static_cast<double>(out.vy_px_s);
          const double v = std::hypot(vx, vy);
          const bool lifetime_ok =
              std::fabs(static_cast<double>(out.lifetime_us) - tau_true) <= 0.02 * tau_true + 1.0;
          const bool direction_ok =
              v > 0 && (vx * std::cos(a) + vy * std::sin(a)) / v > std::cos(0.05);
          good += lifetime_ok && direction_ok;
        }
        ASSERT_GT(checked, 100);
        EXPECT_GE(good, 0.98 * checked)
            << "angle " << angle_deg << " speed " << speed << " reg " << reg;
      }
    }
  }
}

// The surface holds times relative to an epoch in 32 bits (algo/src/
// time_plane.h); the epoch moves when a time leaves the range. An edge swept
// at large, negative, or epoch-crossing times (2^31 us after the first
// event, mid-sweep) gets the estimates it gets at t0 = 1000 us: only the
// RANSAC draws (seeded by the timestamp) differ, which on an exact plane
// changes the fit by rounding at most.
TEST(LifetimeEstimator, EpochMovesKeepTheEstimates) {
  const SensorSize s{24, 20};
  LifetimeOptions o = options_for(s);
  const auto reference_events = straight_edge(s, 0.5, 200.0, 1, 1000);
  LifetimeEstimator reference(o);
  std::vector<AugmentedEvent> expected;
  for (const Event& e : reference_events) expected.push_back(reference.process(e));
  const std::int64_t crossing = (std::int64_t{1} << 31) - 60'000;  // the sweep lasts ~120 ms
  for (const std::int64_t t0 : {std::int64_t{1} << 40, -(std::int64_t{1} << 40), crossing}) {
    LifetimeEstimator est(o);
    est.process(Event{0, 0, 0, -1});  // the other polarity: sets the epoch at t = 0
    int compared = 0;
    for (std::size_t i = 0; i < reference_events.size(); ++i) {
      Event e = reference_events[i];
      e.t_us += t0 - 1000;
      const AugmentedEvent out = est.process(e);
      const AugmentedEvent& want = expected[i];
      ASSERT_EQ(out.is_noise(), want.is_noise()) << "t0 " << t0 << " event " << i;
      if (want.is_noise()) continue;
      EXPECT_NEAR(out.lifetime_us, want.lifetime_us, 1e-3f * want.lifetime_us) << "t0 " << t0 << " event " << i;
      EXPECT_NEAR(out.vx_px_s, want.vx_px_s, 1e-3f * std::fabs(want.vx_px_s) + 1e-3f) << "t0 " << t0 << " event " << i;
      ++compared;
    }
    EXPECT_GT(compared, 200) << "t0 " << t0;
  }
}

TEST(LifetimeEstimator, IsolatedEventIsNoise) {
  LifetimeEstimator est(options_for({64, 64}));
  const AugmentedEvent out = est.process({5000, 30, 30, 1});
  EXPECT_EQ(out.lifetime_us, 0.0f);
  EXPECT_EQ(out.vx_px_s, 0.0f);
  EXPECT_EQ(out.vy_px_s, 0.0f);
  EXPECT_TRUE(out.is_noise());
  EXPECT_FALSE(out.has_prediction());
}

// A noise event long after an edge passed: the window holds only stale
// events of the old edge, which must not support a plane through the new one.
TEST(LifetimeEstimator, EventLongAfterEdgePassedIsNoise) {
  const SensorSize s{40, 40};
  LifetimeEstimator est(options_for(s));
  const auto edge = straight_edge(s, 0.0, 1000.0);
  for (const Event& e : edge) est.process(e);
  const std::int64_t t_last = edge.back().t_us;
  int noise = 0, total = 0;
  for (int k = 0; k < 50; ++k) {
    const Event e{t_last + 20000 + 997 * k, static_cast<std::uint16_t>(5 + (k * 7) % 30),
                  static_cast<std::uint16_t>(5 + (k * 13) % 30), 1};
    noise += est.process(e).is_noise();
    ++total;
  }
  EXPECT_EQ(noise, total);
}

// The same near the border, where only part of the window exists and a few
// stale samples fit a random plane more easily.
TEST(LifetimeEstimator, BorderEventLongAfterEdgePassedIsNoise) {
  const SensorSize s{40, 30};
  LifetimeEstimator est(options_for(s));
  std::int64_t t_last = 0;
  for (double angle : {0.3, 2.0, 4.0}) {  // three passes in different directions
    for (Event e : straight_edge(s, angle, 800.0, 1, t_last + 10000)) {
      est.process(e);
      t_last = e.t_us;
    }
  }
  int noise = 0, total = 0;
  for (int k = 0; k < 120; ++k) {
    const int side = k % 4;
    const int along = (k * 7) % 30;
    const int x = side == 0 ? 0 : side == 1 ? s.width - 1 : std::min(along, s.width - 1);
    const int y = side == 2 ? 0 : side == 3 ? s.height - 1 : std::min(along, s.height - 1);
    const Event e{t_last + 30000 + 1500 * k, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), 1};
    noise += est.process(e).is_noise();
    ++total;
  }
  EXPECT_GE(noise, 0.95 * total);
}

TEST(LifetimeEstimator, PolaritiesHaveSeparateSurfaces) {
  const SensorSize s{40, 40};
  LifetimeEstimator est(options_for(s));
  auto on_edge = straight_edge(s, 0.0, 1000.0, +1);
  for (const Event& e : on_edge) est.process(e);
  // An OFF event in the middle of the ON edge's trail has no OFF support.
  Event off = on_edge[on_edge.size() / 2];
  off.p = -1;
  off.t_us = on_edge.back().t_us + 1;
  EXPECT_TRUE(est.process(off).is_noise());
}

TEST(LifetimeEstimator, BorderEventsUseTheWindowPartInsideTheSensor) {
  const SensorSize s{30, 20};
  LifetimeEstimator est(options_for(s));
  const auto events = straight_edge(s, 0.0, 1000.0);
  int border = 0, border_good = 0;
  for (std::size_t i = 0; i < events.size(); ++i) {
    const AugmentedEvent out = est.process(events[i]);
    const Event& e = events[i];
    if (e.x < 3) continue;  // the edge starts at x = 0: no history yet
    if (e.y == 0 || e.y == s.height - 1) {
      ++border;
      border_good += std::fabs(out.lifetime_us - 1000.0f) < 20.0f;
    }
  }
  ASSERT_GT(border, 40);
  EXPECT_GE(border_good, 0.95 * border);
}

TEST(LifetimeEstimator, OutOfSensorAndBadPolarityAreCountedNotRead) {
  LifetimeEstimator est(options_for({10, 8}));
  EXPECT_TRUE(est.process({1, 10, 0, 1}).is_noise());
  EXPECT_TRUE(est.process({2, 0, 8, 1}).is_noise());
  EXPECT_TRUE(est.process({3, 65535, 65535, -1}).is_noise());
  EXPECT_TRUE(est.process({4, 1, 1, 0}).is_noise());
  EXPECT_EQ(est.stats().out_of_sensor, 3u);
  EXPECT_EQ(est.stats().bad_polarity, 1u);
  EXPECT_EQ(est.stats().events, 4u);
}

// Followers chain: a burst that goes on firing keeps its followers past the
// burst window (each within 2 lifetimes of the one before, all within
// burst_span_lifetimes, 4, of the arrival: an edge blurred over 2.5 px takes
// 2.5 lifetimes to cross a pixel), while an event as late after a single
// event is not a follower.
TEST(LifetimeEstimator, FollowersChainWithinTheBurstSpan) {
  const SensorSize s{40, 40};
  // An edge moving +x at 1000 px/s (lifetime 1 ms); the pixel (20, 20) fires
  // its arrival with the edge and then the events at `delays_us` after it.
  auto late_events = [&](const std::vector<std::int64_t>& delays_us, double span_lifetimes) {
    LifetimeOptions o = options_for(s);
    o.burst_span_lifetimes = span_lifetimes;
    LifetimeEstimator est(o);
    std::vector<Event> events = straight_edge(s, 0.0, 1000.0);
    const Event arrival = *std::find_if(events.begin(), events.end(), [](const Event& e) { return e.x == 20 && e.y == 20; });
    for (const std::int64_t d : delays_us) events.push_back({arrival.t_us + d, arrival.x, arrival.y, arrival.p});
    std::stable_sort(events.begin(), events.end(), [](const Event& a, const Event& b) { return a.t_us < b.t_us; });
    std::vector<AugmentedEvent> late;
    bool arrival_estimated = false;
    for (const Event& e : events) {
      const AugmentedEvent out = est.process(e);
      if (e.x != arrival.x || e.y != arrival.y) continue;
      if (e.t_us == arrival.t_us) {
        arrival_estimated = !out.is_noise();
        continue;
      }
      late.push_back(out);
    }
    EXPECT_TRUE(arrival_estimated);
    EXPECT_EQ(late.size(), delays_us.size());
    return late;
  };
  // A burst firing at 1.5 and 3.0 lifetimes: both follow (3.0 is 1.5 after
  // the one before); 4.5 is past the span.
  const auto chained = late_events({1500, 3000, 4500}, 4.0);
  ASSERT_EQ(chained.size(), 3u);
  EXPECT_NEAR(chained[0].lifetime_us, 1000.0f, 50.0f);
  EXPECT_NEAR(chained[1].lifetime_us, chained[0].lifetime_us, 1e-3f);
  EXPECT_GT(chained[1].vx_px_s, 900.0f);
  EXPECT_TRUE(chained[2].is_noise());
  // 3.0 lifetimes after a single event: 3.0 after the burst's latest, no follower.
  EXPECT_TRUE(late_events({3000}, 4.0)[0].is_noise());
  // A span no longer than the window: followers within 2 lifetimes of the
  // arrival only (the rule before chaining).
  const auto unchained = late_events({1500, 3000}, 2.0);
  EXPECT_NEAR(unchained[0].lifetime_us, 1000.0f, 50.0f);
  EXPECT_TRUE(unchained[1].is_noise());
}

// An edge moving +x at 100 px/s (lifetime 10 ms) where every pixel fires
// `burst` events per crossing (its arrival, then one each 0.5 ms) and pixel
// (20, 20) is hot: from its arrival on it fires every 0.5 ms for 30 ms, at
// 2 kHz, far more events than a crossing has. Returns how many events of
// the hot pixel got a lifetime, and the share of the interior pixels'
// events with the true one (within 10 %).
struct BurstShares {
  int hot_with_lifetime = 0;
  int hot_with_arrival_estimate = 0;  // the lifetime its arrival got: the arrival and its followers
  int hot_events = 0;
  double interior_share = 0.0;
};
BurstShares hot_pixel_in_bursts(int burst, int max_burst_followers) {
  const SensorSize s{40, 40};
  LifetimeOptions o = options_for(s);
  o.max_burst_followers = max_burst_followers;
  LifetimeEstimator est(o);
  std::vector<Event> events;
  for (const Event& arrival : straight_edge(s, 0.0, 100.0)) {
    const bool hot = arrival.x == 20 && arrival.y == 20;
    const int n = hot ? 60 : burst;
    for (int k = 0; k < n; ++k) events.push_back({arrival.t_us + 500 * k, arrival.x, arrival.y, arrival.p});
  }
  std::stable_sort(events.begin(), events.end(), [](const Event& a, const Event& b) { return a.t_us < b.t_us; });
  BurstShares r;
  int interior_events = 0, interior_with_lifetime = 0;
  float arrival_lifetime_us = -1.0f;
  for (const Event& e : events) {
    const AugmentedEvent out = est.process(e);
    const bool with_lifetime = !out.is_noise();
    if (e.x == 20 && e.y == 20) {
      if (r.hot_events++ == 0) arrival_lifetime_us = out.lifetime_us;
      r.hot_with_lifetime += with_lifetime ? 1 : 0;
      r.hot_with_arrival_estimate += with_lifetime && out.lifetime_us == arrival_lifetime_us ? 1 : 0;
    } else if (interior(e, s, 4) && e.x > 8) {  // past the warm-up of the first columns
      ++interior_events;
      interior_with_lifetime += with_lifetime && std::fabs(out.lifetime_us - 10000.0f) < 1000.0f ? 1 : 0;
    }
  }
  r.interior_share = static_cast<double>(interior_with_lifetime) / interior_events;
  return r;
}

// A burst has at most max_burst_followers followers (16): a hot pixel fires
// on, and its events past that are judged on their own (here the first is
// fitted anew, 8.5 ms late, and starts a burst of its own; the last 26 are
// noise), while bursts as long along the whole edge (a low threshold) keep
// theirs, as their upstream neighbours' bursts are as long.
TEST(LifetimeEstimator, AHotPixelKeepsNoMoreFollowersThanItsEdgesBursts) {
  const BurstShares unlimited = hot_pixel_in_bursts(3, 0);
  EXPECT_EQ(unlimited.hot_events, 60);
  EXPECT_GE(unlimited.hot_with_arrival_estimate, 55);  // every event within the burst span: a follower
  const BurstShares limited = hot_pixel_in_bursts(3, 16);
  EXPECT_EQ(limited.hot_with_arrival_estimate, 17);  // the arrival and its 16 followers
  EXPECT_LE(limited.hot_with_lifetime, 40);  // a third of the hot events at least: noise
  EXPECT_GT(limited.interior_share, 0.98);
  // 24 events per crossing everywhere: past 16, the upstream neighbour's
  // burst is as long, so the followers stay.
  const BurstShares long_bursts = hot_pixel_in_bursts(24, 16);
  EXPECT_GT(long_bursts.interior_share, 0.95);
}

// A slow photoreceptor spreads a burst over more than the burst span when
// its timing noise is large against the lifetime: with
// burst_span_timing_noise such a late event stays its burst's follower while
// no newer edge has come from upstream; without it, it arrives anew.
TEST(LifetimeEstimator, SlowResponseFollowersStayInTheirBurst) {
  const SensorSize s{40, 40};
  // An edge moving +x at 5000 px/s (lifetime 200 us), each pixel late by up
  // to 300 us (a slow, noisy pixel); pixel (20, 20) fires once more 600 us
  // after its arrival (3 lifetimes: past the burst window and a burst span
  // of 2).
  std::vector<Event> events = straight_edge(s, 0.0, 5000.0);
  std::mt19937 rng(3);
  for (Event& e : events) e.t_us += static_cast<std::int64_t>(rng() % 300);
  std::stable_sort(events.begin(), events.end(), [](const Event& a, const Event& b) { return a.t_us < b.t_us; });
  const Event arrival = *std::find_if(events.begin(), events.end(), [](const Event& e) { return e.x == 20 && e.y == 20; });
  const Event late_event{arrival.t_us + 600, arrival.x, arrival.y, arrival.p};
  events.insert(std::upper_bound(events.begin(), events.end(), late_event,
                                 [](const Event& a, const Event& b) { return a.t_us < b.t_us; }),
                late_event);
  auto late_output = [&](double timing_noise_factor) {
    LifetimeOptions o = options_for(s);
    o.burst_span_lifetimes = 2.0;
    o.burst_span_timing_noise = timing_noise_factor;
    LifetimeEstimator est(o);
    AugmentedEvent first{}, late{};
    for (const Event& e : events) {
      const AugmentedEvent out = est.process(e);
      if (e.x != arrival.x || e.y != arrival.y) continue;
      (e.t_us == arrival.t_us ? first : late) = out;
    }
    EXPECT_FALSE(first.is_noise());
    return std::pair{first, late};
  };
  const auto [first_on, late_on] = late_output(10.0);
  EXPECT_FALSE(late_on.is_noise());
  EXPECT_EQ(late_on.lifetime_us, first_on.lifetime_us);  // the burst's estimate
  const auto [first_off, late_off] = late_output(0.0);
  EXPECT_NE(late_off.lifetime_us, first_off.lifetime_us);
}

// A burst whose first event came as the edge started, before its neighbours
// fired (too few samples then), gets its estimate at a follower: the plane
// through the burst's arrival with the samples there are now. Not after the
// burst window, and not with followers switched off.
TEST(LifetimeEstimator, FollowerOfAnUnestimatedArrivalGetsThePlaneThroughThatArrival) {
  const SensorSize s{40, 40};
  auto follower_lifetime = [&](double burst_window_lifetimes, std::int64_t follower_delay_us) {
    LifetimeOptions o = options_for(s);
    o.burst_window_lifetimes = burst_window_lifetimes;
    LifetimeEstimator est(o);
    // An edge entering at column 10, moving +x at 1000 px/s (lifetime 1 ms).
    std::vector<Event> edge;
    for (const Event& e : straight_edge(s, 0.0, 1000.0)) {
      if (e.x >= 10) edge.push_back({e.t_us - 10'000, e.x, e.y, e.p});
    }
    const Event arrival =
        *std::find_if(edge.begin(), edge.end(), [](const Event& e) { return e.x == 10 && e.y == 20; });
    bool arrival_was_noise = false;
    AugmentedEvent follower;
    const Event late{arrival.t_us + follower_delay_us, arrival.x, arrival.y, arrival.p};
    bool sent = false;
    for (const Event& e : edge) {
      if (!sent && e.t_us > late.t_us) {
        follower = est.process(late);
        sent = true;
      }
      const AugmentedEvent out = est.process(e);
      if (e.x == arrival.x && e.y == arrival.y) arrival_was_noise = out.is_noise();
    }
    EXPECT_TRUE(arrival_was_noise);  // the edge had just begun: nothing behind it
    EXPECT_TRUE(sent);
    return follower;
  };
  const AugmentedEvent f = follower_lifetime(2.0, 1500);
  EXPECT_NEAR(f.lifetime_us, 1000.0f, 50.0f);
  EXPECT_GT(f.vx_px_s, 900.0f);
  EXPECT_NEAR(f.vy_px_s, 0.0f, 100.0f);
  EXPECT_TRUE(follower_lifetime(2.0, 2500).is_noise());  // after 2 lifetimes: not a follower
  EXPECT_TRUE(follower_lifetime(0.0, 1500).is_noise());  // followers off: the paper
}

// An edge entering a sensor whose pixels fire sparsely (60 % stay silent, a
// contrast below their thresholds): every window holds fewer samples than
// eq. 8 assumes, and pixels ahead have never fired. Counting those as outside
// the window (fresh_region_span_us) labels most of the edge, with the right
// lifetime; a slow edge (supporters older than the span) is left to eq. 8
// and the continuations, as before.
struct SparseEdgeResult {
  double share = 0.0;             // of the interior events, with a lifetime
  double median_rel_error = 0.0;  // |lifetime - truth| / truth
  std::vector<float> lifetimes_us;
};
SparseEdgeResult sparse_edge(double speed_px_s, double fresh_region_span_us) {
  const SensorSize s{60, 40};
  LifetimeOptions o = options_for(s);
  o.fresh_region_span_us = fresh_region_span_us;
  LifetimeEstimator est(o);
  const double truth_us = 1e6 / speed_px_s;
  SparseEdgeResult r;
  std::vector<double> errors;
  int interior_events = 0, estimated = 0;
  for (const Event& e : straight_edge(s, 0.0, speed_px_s)) {
    if ((e.x * 7 + e.y * 13) % 10 < 6) continue;  // silent pixels
    const AugmentedEvent out = est.process(e);
    r.lifetimes_us.push_back(out.lifetime_us);
    if (!interior(e, s, 2)) continue;
    ++interior_events;
    if (out.is_noise()) continue;
    ++estimated;
    errors.push_back(std::fabs(static_cast<double>(out.lifetime_us) - truth_us) / truth_us);
  }
  r.share = static_cast<double>(estimated) / interior_events;
  if (!errors.empty()) {
    std::nth_element(errors.begin(), errors.begin() + static_cast<std::ptrdiff_t>(errors.size() / 2), errors.end());
    r.median_rel_error = errors[errors.size() / 2];
  }
  return r;
}

TEST(LifetimeEstimator, SparseEdgeEnteringAFreshRegionGetsItsLifetime) {
  const SparseEdgeResult on = sparse_edge(1000.0, 20'000.0);
  const SparseEdgeResult off = sparse_edge(1000.0, 0.0);
  std::printf("sparse edge, 1000 px/s: with a lifetime %.3f (rule off %.3f), median error %.4f (off %.4f)\n",
              on.share, off.share, on.median_rel_error, off.median_rel_error);
  EXPECT_GE(on.share, 0.9);
  EXPECT_GE(on.share, off.share + 0.2);
  EXPECT_LE(on.median_rel_error, 0.05);
}

TEST(LifetimeEstimator, FreshRegionRuleHoldsOnlyWithinItsSpan) {
  // 30 px/s: lifetime 33 ms, every supporter older than a 20 ms span.
  const SparseEdgeResult within = sparse_edge(30.0, 20'000.0);
  const SparseEdgeResult off = sparse_edge(30.0, 0.0);
  const SparseEdgeResult long_span = sparse_edge(30.0, 1e6);
  std::printf("sparse edge, 30 px/s: with a lifetime %.3f at a 20 ms span, %.3f off, %.3f at 1 s\n", within.share,
              off.share, long_span.share);
  EXPECT_EQ(within.lifetimes_us, off.lifetimes_us);
  EXPECT_GE(long_span.share, off.share + 0.2);
}

// Every event labelled noise is counted under one reason (evlife process
// prints them): too few past events, no supported plane, an unresolved fit.
TEST(LifetimeEstimator, EveryNoiseEventIsCountedUnderOneReason) {
  const SensorSize s{40, 40};
  LifetimeEstimator est(options_for(s));
  EXPECT_TRUE(est.process({1000, 30, 30, -1}).is_noise());  // nothing around it
  EXPECT_EQ(est.stats().noise_few_samples, 1u);

  // A readout that stamps a whole block with one timestamp: a flat plane,
  // whose lifetime the timestamps cannot resolve.
  for (std::uint16_t y = 2; y < 12; ++y)
    for (std::uint16_t x = 2; x < 12; ++x) est.process({2000, x, y, -1});
  const std::uint64_t unresolved = est.stats().noise_unresolved;
  EXPECT_GT(unresolved, 20u);

  // Events long after an edge passed: samples enough, no plane through them.
  const auto edge = straight_edge(s, 0.0, 1000.0, 1, 5000);
  for (const Event& e : edge) est.process(e);
  const std::uint64_t unsupported = est.stats().noise_unsupported;
  for (int k = 0; k < 20; ++k) {
    est.process({edge.back().t_us + 20000 + 997 * k, static_cast<std::uint16_t>(5 + (k * 7) % 30),
                 static_cast<std::uint16_t>(5 + (k * 13) % 30), 1});
  }
  EXPECT_EQ(est.stats().noise_unsupported, unsupported + 20);
  EXPECT_EQ(est.stats().noise_unresolved, unresolved);
  est.process({9, 50, 0, 1});  // outside the sensor

  const LifetimeStats& st = est.stats();
  EXPECT_EQ(st.noise, st.noise_few_samples + st.noise_unsupported + st.noise_unresolved + st.out_of_sensor +
                          st.bad_polarity + st.time_out_of_range);
}

// An hour without events, then the same edges again: the 32-bit surface
// saturates the old times, and the differences taken with them must not
// overflow (signed overflow, caught by the CI's UBSan pass: the shift of a
// burst's samples to its arrival was taken in 32 bits). Times beyond +-2^62 us
// are rejected and counted, as out-of-sensor events are.
TEST(LifetimeEstimator, HoursOfIdleAndTimesAtTheEndsOfTheClockAreWellDefined) {
  const SensorSize s{64, 64};
  LifetimeEstimator est(options_for(s));
  std::uint64_t with_lifetime[2] = {0, 0};
  for (int pass = 0; pass < 2; ++pass) {
    for (int x = 0; x < 40; ++x) {
      for (int y = 0; y < 10; ++y) {
        const AugmentedEvent a = est.process(
            Event{pass * std::int64_t{3'300'000'000} + x * 500, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), 1});
        with_lifetime[pass] += a.is_noise() ? 0u : 1u;
      }
    }
  }
  EXPECT_GT(with_lifetime[0], 200u);
  EXPECT_GT(with_lifetime[1], 200u);  // the edge after the hour is estimated as the first was

  EXPECT_TRUE(est.process(Event{std::numeric_limits<std::int64_t>::min(), 1, 1, 1}).is_noise());
  EXPECT_TRUE(est.process(Event{kMaxEventTimeUs + 1, 1, 1, 1}).is_noise());
  EXPECT_FALSE(within_event_time_range(-kMaxEventTimeUs - 1));
  EXPECT_TRUE(within_event_time_range(-kMaxEventTimeUs));
  EXPECT_TRUE(within_event_time_range(kMaxEventTimeUs));
  const LifetimeStats& st = est.stats();
  EXPECT_EQ(st.time_out_of_range, 2u);
  EXPECT_EQ(st.noise, st.noise_few_samples + st.noise_unsupported + st.noise_unresolved + st.out_of_sensor +
                          st.bad_polarity + st.time_out_of_range);
}

// Both ends of the time range, kMaxEventTimeUs apart twice over: an edge at
// -2^62 us leaves predictions and stored times, then one at +2^62 us. The
// epoch (2^30 below a time) made differences up to 2^63 + 2^30: signed
// overflow in fits_epoch, rebase and the prediction's error (UBSan, in CI's
// ASan+UBSan pass). The second edge is estimated as the first was, with no
// prediction from the first (it expired: the edge had passed long before).
TEST(LifetimeEstimator, EdgesAtBothEndsOfTheTimeRangeAreEstimatedAlike) {
  LifetimeEstimator est(options_for({40, 10}));
  std::uint64_t with_lifetime[2] = {0, 0}, predicted[2] = {0, 0};
  for (int pass = 0; pass < 2; ++pass) {
    const std::int64_t start = pass == 0 ? -kMaxEventTimeUs : kMaxEventTimeUs - 40 * 500;
    for (int x = 0; x < 40; ++x) {
      for (int y = 0; y < 10; ++y) {
        const AugmentedEvent a =
            est.process(Event{start + x * 500, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), 1});
        with_lifetime[pass] += a.is_noise() ? 0u : 1u;
        predicted[pass] += a.has_prediction() ? 1u : 0u;
      }
    }
  }
  // (The first edge's times saturate to the oldest storable: still past
  // events, one more supporter here and there.)
  EXPECT_GT(with_lifetime[0], 200u);
  EXPECT_NEAR(static_cast<double>(with_lifetime[1]), static_cast<double>(with_lifetime[0]), 5.0);
  EXPECT_NEAR(static_cast<double>(predicted[1]), static_cast<double>(predicted[0]), 5.0);
  // The other polarity at the first edge's start, 2^63 us earlier (in order
  // for its polarity; the polarities share the surface's epoch): a rebase by
  // -2^63 over stored times, then back.
  (void)est.process(Event{-kMaxEventTimeUs, 39, 0, -1});
  (void)est.process(Event{kMaxEventTimeUs, 39, 1, 1});
  EXPECT_EQ(est.stats().time_out_of_range, 0u);
  EXPECT_EQ(est.stats().time_backwards, 0u);
}

// A camera's clock restarted without reset(): the events of the second pass
// come earlier than the last of their polarity. They were read as followers
// of the bursts of the first pass (a negative age passed the burst test) and
// took its estimates, uncounted; they are rejected and counted now, the
// other polarity is unaffected, and after reset() the pass is estimated as
// the first was.
TEST(LifetimeEstimator, TimeGoingBackwardsPerPolarityIsRejectedAndCounted) {
  LifetimeEstimator est(options_for({40, 10}));
  const auto edge = [&est](std::int64_t start_us, int p) {
    std::uint64_t with_lifetime = 0;
    for (int x = 0; x < 40; ++x) {
      for (int y = 0; y < 10; ++y) {
        const AugmentedEvent a = est.process(Event{start_us + x * 500, static_cast<std::uint16_t>(x),
                                                   static_cast<std::uint16_t>(y), static_cast<std::int8_t>(p)});
        with_lifetime += a.is_noise() ? 0u : 1u;
      }
    }
    return with_lifetime;
  };
  const std::uint64_t first = edge(1'000'000, 1);
  EXPECT_GT(first, 200u);
  EXPECT_EQ(edge(0, 1), 0u);  // the clock restarted at 0: every event before the first pass's last
  EXPECT_EQ(est.stats().time_backwards, 400u);
  // (Estimated alike: the random draws differ with the times, so not bit for bit.)
  EXPECT_NEAR(static_cast<double>(edge(0, -1)), static_cast<double>(first), 5.0);  // OFF: its own order
  EXPECT_EQ(est.stats().time_backwards, 400u);
  EXPECT_EQ(est.stats().rejected(), 400u);
  EXPECT_NE(rejected_events_text(est.stats()).find("400 time going backwards"), std::string::npos);
  est.reset();
  EXPECT_NEAR(static_cast<double>(edge(0, 1)), static_cast<double>(first), 5.0);
  EXPECT_EQ(est.stats().time_backwards, 0u);
  EXPECT_EQ(rejected_events_text(est.stats()).find("backwards"), std::string::npos);
}

// Durations (info, process, eval summaries) keep the microsecond at any
// time: 2 us at 2^55 us read 0 (each time converted to double first).
TEST(EventTimes, SecondsBetweenKeepsTheMicrosecondAtAnyTime) {
  EXPECT_EQ(evlife::seconds_between(36'028'797'018'963'969, 36'028'797'018'963'971), 2e-6);
  EXPECT_EQ(evlife::seconds_between(-5, 7), 12e-6);
  EXPECT_DOUBLE_EQ(evlife::seconds_between(INT64_MIN, INT64_MAX), 18446744073709.551615);  // beyond int64: in double
}

// Prediction errors are differences of two nearby times: near 2^62 us they
// keep the microsecond (they were rounded to 1024 us, most of them to 0).
TEST(LifetimeEstimator, PredictionErrorsNearTheEndOfTheTimeRangeKeepTheMicrosecond) {
  std::vector<double> errors[2];
  for (int pass = 0; pass < 2; ++pass) {
    LifetimeEstimator est(options_for({40, 10}));
    const std::int64_t start = pass == 0 ? 0 : kMaxEventTimeUs - 40 * 500;
    std::vector<Event> events;
    for (int x = 0; x < 40; ++x) {
      for (int y = 0; y < 10; ++y) {
        const std::int64_t jitter_us = (x * 7 + y * 13) % 11;  // latency jitter: errors of a few us
        events.push_back(Event{start + x * 500 + jitter_us, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), 1});
      }
    }
    std::stable_sort(events.begin(), events.end(), [](const Event& a, const Event& b) { return a.t_us < b.t_us; });
    for (const Event& e : events) {
      const AugmentedEvent a = est.process(e);
      if (a.has_prediction()) errors[pass].push_back(std::fabs(static_cast<double>(a.prediction_error_us)));
    }
  }
  for (int pass = 0; pass < 2; ++pass) {
    ASSERT_GT(errors[pass].size(), 100u) << "pass " << pass;
    const auto zeros = std::count(errors[pass].begin(), errors[pass].end(), 0.0);
    EXPECT_LT(static_cast<double>(zeros), 0.2 * static_cast<double>(errors[pass].size())) << "pass " << pass;
    EXPECT_LT(*std::max_element(errors[pass].begin(), errors[pass].end()), 100.0) << "pass " << pass;
  }
}

// A moved-from estimator (std::optional, containers) has no per-pixel state
// left: every event is labelled noise and counted out_of_sensor (it read a
// null plane before); the estimator moved to works on.
TEST(LifetimeEstimator, AMovedFromEstimatorReadsNothing) {
  LifetimeEstimator a(options_for({64, 64}));
  LifetimeEstimator b(std::move(a));
  EXPECT_TRUE(a.process(Event{1000, 10, 10, 1}).is_noise());  // NOLINT(bugprone-use-after-move): the point
  EXPECT_EQ(a.stats().out_of_sensor, 1u);
  std::vector<Event> none(4, Event{2000, 11, 10, 1});
  std::vector<AugmentedEvent> out(4);
  EXPECT_EQ(a.process(none, out), 4u);  // the batch form's prefetch too
  b.process(Event{1000, 10, 10, 1});
  EXPECT_EQ(b.stats().out_of_sensor, 0u);
  LifetimeEstimator c(options_for({8, 8}));
  c = std::move(b);
  EXPECT_EQ(b.stats().events, 1u);  // NOLINT(bugprone-use-after-move)
  EXPECT_TRUE(b.process(Event{3000, 10, 10, 1}).is_noise());  // NOLINT(bugprone-use-after-move)
  EXPECT_EQ(b.stats().out_of_sensor, 1u);  // NOLINT(bugprone-use-after-move)
  EXPECT_EQ(c.process(Event{3000, 10, 10, 1}).event.x, 10);
  EXPECT_EQ(c.stats().out_of_sensor, 0u);
  // A self-move empties the planes: the estimator then reads nothing (it
  // kept its sensor size and read the empty planes: a crash).
  auto& same = c;
  c = std::move(same);
  EXPECT_TRUE(c.process(Event{4000, 10, 10, 1}).is_noise());
  EXPECT_EQ(c.stats().out_of_sensor, 1u);
}

// Each polarity's surface has its own time origin: a jump of one polarity's
// clock (one corrupt ON timestamp 2^32 us ahead) leaves every OFF estimate as
// without it (they changed, uncounted: both planes were moved), and clocks
// 2^32 us apart per polarity estimate as one estimator per polarity (every
// switch of polarity walked the whole surface, and 99 % became noise).
TEST(LifetimeEstimator, APolaritysClockJumpMovesNothingOfTheOther) {
  const SensorSize s{48, 36};
  std::vector<Event> events;
  for (const Event& e : straight_edge(s, 0.4, 1500.0)) {
    events.push_back(e);
    events.push_back(Event{e.t_us + 7, e.x, e.y, static_cast<std::int8_t>(-e.p)});  // the other polarity too
  }
  const auto off_outputs = [&s](const std::vector<Event>& in) {
    LifetimeEstimator est(options_for(s));
    std::vector<AugmentedEvent> out;
    for (const Event& e : in) {
      const AugmentedEvent a = est.process(e);
      if (a.event.p < 0) out.push_back(a);
    }
    return out;
  };
  const std::vector<AugmentedEvent> reference = off_outputs(events);
  std::vector<Event> glitched = events;
  const std::size_t middle = glitched.size() / 2;
  const Event before = glitched[middle];
  glitched.insert(glitched.begin() + static_cast<std::ptrdiff_t>(middle),
                  Event{before.t_us + (std::int64_t{1} << 32), before.x, before.y, 1});
  const std::vector<AugmentedEvent> after_glitch = off_outputs(glitched);
  ASSERT_EQ(after_glitch.size(), reference.size());
  std::size_t with_lifetime = 0;
  for (std::size_t i = 0; i < reference.size(); ++i) {
    ASSERT_EQ(std::memcmp(&after_glitch[i], &reference[i], sizeof(AugmentedEvent)), 0) << "OFF event " << i;
    with_lifetime += reference[i].is_noise() ? 0u : 1u;
  }
  EXPECT_GT(with_lifetime, reference.size() / 2);
  // Clocks apart: ON as it is, OFF 2^32 us ahead, against one estimator per polarity.
  std::vector<Event> apart = events;
  for (Event& e : apart) e.t_us += e.p < 0 ? (std::int64_t{1} << 32) : 0;
  LifetimeEstimator both(options_for(s)), on(options_for(s)), off(options_for(s));
  std::size_t differ = 0;
  for (const Event& e : apart) {
    const AugmentedEvent a = both.process(e);
    const AugmentedEvent alone = (e.p > 0 ? on : off).process(e);
    differ += std::memcmp(&a, &alone, sizeof a) != 0 ? 1u : 0u;
  }
  EXPECT_EQ(differ, 0u);
  EXPECT_EQ(both.stats().time_backwards, 0u);
}

TEST(LifetimeEstimator, ConstantVelocityEdgeIsPredictedWell) {
  const SensorSize s{48, 36};
  LifetimeEstimator est(options_for(s));
  const auto events = straight_edge(s, 0.4, 1500.0);
  int with_prediction = 0, small_error = 0;
  for (const Event& e : events) {
    const AugmentedEvent out = est.process(e);
    if (!out.has_prediction()) continue;
    ++with_prediction;
    small_error += std::fabs(static_cast<double>(out.prediction_error_us)) < 0.1 * 1e6 / 1500.0;
  }
  EXPECT_GT(with_prediction, static_cast<int>(events.size()) / 2);
  EXPECT_GE(small_error, 0.95 * with_prediction);
  EXPECT_EQ(est.stats().predictions, static_cast<std::uint64_t>(with_prediction));
}

// A prediction is for the edge that made it. Column 20 misses the edge (its
// pixels do not fire); their next events, 30 ms later, belong to another
// edge: no prediction with the default expiry, a 30 ms "error" without it.
// Events just behind the predicted time (half a lifetime late) keep theirs.
TEST(LifetimeEstimator, PredictionsExpireWhenTheEdgeMissedThePixel) {
  const SensorSize s{40, 30};
  const double speed_px_s = 1000.0;  // lifetime 1 ms, moving along +x
  std::vector<Event> edge;
  for (const Event& e : straight_edge(s, 0.0, speed_px_s))
    if (e.x != 20) edge.push_back(e);
  auto late_events_at_column_20 = [&](std::int64_t delay_us) {
    std::vector<Event> late;
    const std::int64_t t_col20 = 1000 + 20 * 1000;  // when the edge passed column 20
    for (std::uint16_t y = 5; y < 25; ++y) late.push_back({t_col20 + delay_us, 20, y, 1});
    return late;
  };
  for (const double expiry : {0.0, 2.0}) {
    for (const std::int64_t delay_us : {std::int64_t{500}, std::int64_t{30000}}) {
      LifetimeOptions o = options_for(s);
      o.prediction_expiry_lifetimes = expiry;
      LifetimeEstimator est(o);
      std::vector<Event> events = edge;
      const auto late = late_events_at_column_20(delay_us);
      events.insert(events.end(), late.begin(), late.end());
      std::stable_sort(events.begin(), events.end(), [](const Event& a, const Event& b) { return a.t_us < b.t_us; });
      int predicted = 0;
      for (const Event& e : events) {
        const AugmentedEvent out = est.process(e);
        if (e.x == 20) predicted += out.has_prediction();
      }
      const bool expect_predictions = expiry == 0.0 || delay_us == 500;
      EXPECT_EQ(predicted, expect_predictions ? 20 : 0) << "expiry " << expiry << ", delay " << delay_us << " us";
    }
  }
}

TEST(LifetimeEstimator, DeterministicAndBatchEqualsPerEvent) {
  const SensorSize s{48, 36};
  auto events = straight_edge(s, 1.0, 3000.0);
  // Some pseudo-random noise so RANSAC has outliers to reject.
  std::uint32_t r = 12345;
  for (int k = 0; k < 500; ++k) {
    r = r * 1664525u + 1013904223u;
    events.push_back({static_cast<std::int64_t>(r % 20000), static_cast<std::uint16_t>(r % 48),
                      static_cast<std::uint16_t>((r >> 8) % 36), (r >> 20) & 1 ? std::int8_t{1} : std::int8_t{-1}});
  }
  std::stable_sort(events.begin(), events.end(), [](const Event& a, const Event& b) { return a.t_us < b.t_us; });
  LifetimeEstimator a(options_for(s)), b(options_for(s));
  std::vector<AugmentedEvent> out_a(events.size()), out_b(events.size());
  for (std::size_t i = 0; i < events.size(); ++i) out_a[i] = a.process(events[i]);
  ASSERT_EQ(b.process(events, out_b), events.size());
  EXPECT_EQ(std::memcmp(out_a.data(), out_b.data(), out_a.size() * sizeof(AugmentedEvent)), 0);
  a.reset();
  for (std::size_t i = 0; i < events.size(); ++i) out_b[i] = a.process(events[i]);
  EXPECT_EQ(std::memcmp(out_a.data(), out_b.data(), out_a.size() * sizeof(AugmentedEvent)), 0);
}

TEST(LifetimeEstimator, FactoryEstimatorEqualsConstructedOne) {
  const SensorSize s{48, 36};
  const auto events = straight_edge(s, 0.7, 2500.0);
  LifetimeEstimatorOrError made = make_lifetime_estimator(options_for(s));
  ASSERT_TRUE(made) << made.error;
  EXPECT_TRUE(made.error.empty());
  LifetimeEstimator constructed(options_for(s));
  std::vector<AugmentedEvent> out_a(events.size()), out_b(events.size());
  ASSERT_EQ(made.estimator->process(events, out_a), events.size());
  ASSERT_EQ(constructed.process(events, out_b), events.size());
  EXPECT_GT(made.estimator->stats().events - made.estimator->stats().noise, events.size() / 2);
  EXPECT_EQ(std::memcmp(out_a.data(), out_b.data(), out_a.size() * sizeof(AugmentedEvent)), 0);
  // The message the README and make_lifetime_estimator.h quote (it read
  // "must be in odd, [3, 15]" where they said "must be odd, in 3..15").
  LifetimeOptions even = options_for(s);
  even.window_size = 4;
  const LifetimeEstimatorOrError refused = make_lifetime_estimator(even);
  EXPECT_FALSE(refused);
  EXPECT_EQ(refused.error, "LifetimeOptions.window_size: 4 must be odd, in [3, 15]");
  // A value just outside its range is shown as given, not rounded into the range beside it
  // ("0.900000 must be in (0, 0.9]", "-0.000000 must be in [0, 1000]": a review's finding).
  LifetimeOptions outside = options_for(s);
  outside.outlier_fraction = 0.9000001;
  EXPECT_EQ(make_lifetime_estimator(outside).error,
            "LifetimeOptions.outlier_fraction: 0.9000001 must be in (0, 0.9]");
  outside = options_for(s);
  outside.lambda_decay_per_us = -1e-9;
  EXPECT_EQ(make_lifetime_estimator(outside).error, "LifetimeOptions.lambda_decay_per_us: -1e-09 must be in [0, 1000]");
}

TEST(LifetimeEstimator, ProcessIsNoexcept) {
  LifetimeEstimator est(options_for({8, 8}));
  static_assert(noexcept(est.process(Event{})));
  static_assert(noexcept(est.process(std::span<const Event>{}, std::span<AugmentedEvent>{})));
  SUCCEED();
}

}  // namespace
}  // namespace evlife
