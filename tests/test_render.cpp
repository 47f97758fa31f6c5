// Rendering of active events, checked against synthetic augmented events whose
// lifetimes are exact by construction (a straight edge at speed s needs 1/s to
// move one pixel). No estimator involved: this tests render/ alone.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "evlife/algo/active_event_map.h"
#include "evlife/render/augmented_source.h"
#include "evlife/render/fixed_window_map.h"
#include "evlife/render/frame_clock.h"
#include "evlife/render/frame_composer.h"
#include "evlife/render/frame_painter.h"
#include "evlife/render/histogram.h"
#include "evlife/render/plot.h"
#include "evlife/render/lifetime_colormap.h"
#include "evlife/render/output_kind.h"
#include "evlife/render/render_cursor.h"
#include "evlife/render/sharpness.h"

namespace {

using evlife::AugmentedEvent;
using evlife::Event;
using evlife::SensorSize;
using evlife::ActiveEventMap;
using evlife::render::FixedWindowMap;

constexpr SensorSize kSensor{128, 96};
constexpr std::int64_t kT0 = 1'000'000;  // not zero: time origin must not matter

// A vertical edge moving in +x; column x fires (every row) when the edge
// reaches it. `lifetime_us(x)` gives what the "estimator" assigned.
template <class Lifetime>
std::vector<AugmentedEvent> moving_edge(const std::vector<std::int64_t>& column_t_us, Lifetime lifetime_us,
                                        float vx_px_s) {
  std::vector<AugmentedEvent> out;
  for (int x = 0; x < static_cast<int>(column_t_us.size()); ++x)
    for (int y = 0; y < kSensor.height; ++y) {
      AugmentedEvent a;
      a.event = Event{column_t_us[static_cast<std::size_t>(x)], static_cast<std::uint16_t>(x),
                      static_cast<std::uint16_t>(y), 1};
      a.lifetime_us = lifetime_us(x);
      a.vx_px_s = vx_px_s;
      a.vy_px_s = 0.0f;
      out.push_back(a);
    }
  return out;
}

std::vector<std::int64_t> constant_speed_times(double speed_px_s) {
  std::vector<std::int64_t> t(static_cast<std::size_t>(kSensor.width));
  for (int x = 0; x < kSensor.width; ++x)
    t[static_cast<std::size_t>(x)] = kT0 + std::llround(x * 1e6 / speed_px_s);
  return t;
}

// Feeds events with t <= t_us (they are sorted) starting at `next`.
template <class Sink>
void feed_until(const std::vector<AugmentedEvent>& events, std::size_t& next, std::int64_t t_us, Sink& sink) {
  while (next < events.size() && events[next].event.t_us <= t_us) sink.feed(events[next++]);
}

// Active columns of one row, as a list.
std::vector<int> active_columns(const ActiveEventMap& set, int y, std::int64_t t_us) {
  std::vector<int> cols;
  for (int x = 0; x < kSensor.width; ++x)
    if (set.is_active(x, y, t_us)) cols.push_back(x);
  return cols;
}

TEST(LifetimeColormap, LegendLabelsSayTheirTicksValue) {
  EXPECT_EQ(evlife::render::lifetime_tick_label(10), "0.01 ms");  // was "0.0 ms"
  EXPECT_EQ(evlife::render::lifetime_tick_label(50), "0.05 ms");  // was "0.1 ms"
  EXPECT_EQ(evlife::render::lifetime_tick_label(500), "0.5 ms");
  EXPECT_EQ(evlife::render::lifetime_tick_label(20'000), "20 ms");
  EXPECT_EQ(evlife::render::lifetime_tick_label(1e8), "100 s");  // "100000 ms" ran off the panel
}

// A range with no 1-2-5 value inside (--lifetime-range 6:9) is labelled at
// its ends: its legend had no label at all, and the colours could not be read.
TEST(LifetimeColormap, ANarrowRangeIsLabelledAtItsEnds) {
  const auto label_pixels = [](double min_us, double max_us) {
    const cv::Mat legend = evlife::render::LifetimeColormap(min_us, max_us).legend(200);
    int n = 0;
    for (int y = 24; y < legend.rows; ++y)  // below the title, right of the bar and its ticks
      for (int x = 29; x < legend.cols; ++x) n += legend.at<cv::Vec3b>(y, x)[1] > 128 ? 1 : 0;
    return n;
  };
  EXPECT_GT(label_pixels(300.0, 30'000.0), 0);
  const int narrow = label_pixels(6000.0, 9000.0);
  EXPECT_GT(narrow, 0);
  EXPECT_GT(label_pixels(3000.0, 4000.0), 0);
  // A range of hundreds of decades (--lifetime-range 1e-300:1e9 in ms) keeps at most 7 ticks (it
  // drew one per decade, ~300 overprinted labels): the tick marks are white at x = 6 + 16 + 2.
  const auto ticks = [](double min_us, double max_us) {
    const cv::Mat legend = evlife::render::LifetimeColormap(min_us, max_us).legend(400);
    int n = 0;
    for (int y = 24; y < legend.rows; ++y) n += legend.at<cv::Vec3b>(y, 24) == cv::Vec3b(255, 255, 255) ? 1 : 0;
    return n;
  };
  EXPECT_GE(ticks(300.0, 30'000.0), 3);
  EXPECT_LE(ticks(1e-297, 1e12), 7);
  EXPECT_GE(ticks(1e-297, 1e12), 2);
}

TEST(ActiveEventMap, ConstantSpeedEdgeIsAThinLineAtTheEdgeWhateverTheSpeed) {
  for (const double speed : {40.0, 230.0, 1000.0, 4700.0, 25000.0}) {
    for (const bool thinning : {true, false}) {
      SCOPED_TRACE("speed " + std::to_string(speed) + " px/s, thinning " + std::to_string(thinning));
      const auto times = constant_speed_times(speed);
      const float lifetime = static_cast<float>(1e6 / speed);
      const auto events = moving_edge(times, [&](int) { return lifetime; }, static_cast<float>(speed));
      ActiveEventMap set(kSensor, thinning);
      std::size_t next = 0;
      // Instants that are no multiple of any frame period, across the whole sweep.
      const double duration_us = (kSensor.width - 1) * 1e6 / speed;
      for (const double frac : {0.013, 0.137, 0.2718, 0.5, 0.61803, 0.9})
      {
        const std::int64_t t = kT0 + std::llround(frac * duration_us) + 7;
        feed_until(events, next, t, set);
        const double edge_x = (static_cast<double>(t - kT0)) * speed / 1e6;  // true position
        for (int y : {0, 17, kSensor.height - 1}) {
          const auto cols = active_columns(set, y, t);
          ASSERT_GE(cols.size(), 1u) << "t=" << t;
          ASSERT_LE(cols.size(), 2u) << "t=" << t;
          for (int c : cols) EXPECT_NEAR(c, edge_x, 1.0) << "t=" << t;
        }
      }
    }
  }
}

TEST(FixedWindowMap, EdgeIsSpeedTimesWindowThick) {
  for (const double speed : {40.0, 230.0, 1000.0, 3000.0}) {
    for (const std::int64_t window_us : {std::int64_t{1000}, std::int64_t{30000}}) {
      const double expected = speed * static_cast<double>(window_us) / 1e6;  // pixels crossed
      if (expected > kSensor.width / 2.0) continue;
      SCOPED_TRACE("speed " + std::to_string(speed) + " window " + std::to_string(window_us));
      const auto times = constant_speed_times(speed);
      const auto events = moving_edge(times, [&](int) { return static_cast<float>(1e6 / speed); },
                                      static_cast<float>(speed));
      FixedWindowMap map(kSensor);
      std::size_t next = 0;
      const std::int64_t t = kT0 + std::llround((kSensor.width * 0.75) * 1e6 / speed) + 123;
      feed_until(events, next, t, map);
      int thickness = 0;
      for (int x = 0; x < kSensor.width; ++x)
        thickness += map.is_active(5u * static_cast<std::size_t>(kSensor.width) + static_cast<std::size_t>(x), t, window_us) ? 1 : 0;
      // Columns whose firing time lies in [t - window, t]: speed*window, +-1 for rounding.
      EXPECT_NEAR(thickness, expected, 1.0);
      if (expected > 3) {
        EXPECT_GT(thickness, 2);
      }
    }
  }
}

// The "estimator" keeps the lifetime of the initial speed while the edge
// accelerates tenfold: lifetimes are overestimated, as in paper III-B.3.
struct AcceleratingEdge {
  std::vector<std::int64_t> times;
  std::vector<AugmentedEvent> events;
};
AcceleratingEdge accelerating_edge() {
  const double v0 = 200.0, a = 20000.0;  // px/s, px/s^2
  AcceleratingEdge e;
  for (int x = 0; x < kSensor.width; ++x) {
    const double t_s = (-v0 + std::sqrt(v0 * v0 + 2 * a * x)) / a;  // x = v0 t + a t^2 / 2
    e.times.push_back(kT0 + std::llround(t_s * 1e6));
  }
  e.events = moving_edge(e.times, [&](int) { return static_cast<float>(1e6 / v0); },
                         static_cast<float>(v0));
  return e;
}

// Times at both ends of int64 (an evlife output may hold any): windows stay
// exact, no difference overflows (UBSan: t - epoch in feed, the rebase and
// the window bounds).
TEST(FixedWindowMap, TimesAtBothEndsOfTheClock) {
  evlife::render::FixedWindowMap map({4, 1});
  map.feed(Event{INT64_MIN, 0, 0, 1});
  EXPECT_EQ(map.count_active(INT64_MIN, 1000), 1u);
  map.feed(Event{-5, 1, 0, 1});
  EXPECT_EQ(map.count_active(-5, 1000), 1u);  // INT64_MIN is long past
  map.feed(Event{INT64_MAX, 2, 0, -1});
  EXPECT_EQ(map.count_active(INT64_MAX, 1000), 1u);
  EXPECT_EQ(map.count_active(INT64_MAX, evlife::render::FixedWindowMap::kLongestWindowUs), 1u);
  EXPECT_EQ(map.polarity(2), -1);
}

// One event older than the map's epoch (a corrupt time, a restarted clock,
// fed by run's render stage after the estimator rejected it): counted and
// ignored. Taken for a jump forward, it moved the epoch and erased every
// pixel's history (the window drew nothing).
TEST(FixedWindowMap, AnEventOlderThanItsRangeIsCountedNotAWipe) {
  evlife::render::FixedWindowMap map({4, 1});
  map.feed(Event{0, 0, 0, 1});
  map.feed(Event{3'000'000'000, 1, 0, 1});
  ASSERT_EQ(map.count_active(3'000'000'000, 1'000'000), 1u);
  map.feed(Event{1'000'000, 2, 0, 1});
  EXPECT_EQ(map.count_active(3'000'000'000, 1'000'000), 1u);
  EXPECT_TRUE(map.is_active(1, 3'000'000'000, 1'000'000));
  EXPECT_EQ(map.late(), 1u);
  map.feed(Event{3'000'000'100, 2, 0, -1});  // and goes on
  EXPECT_EQ(map.count_active(3'000'000'100, 1'000'000), 2u);
}

TEST(ActiveEventMap, AcceleratingEdgeStaysThinWithEdgeThinningOnly) {
  const auto edge = accelerating_edge();
  const std::int64_t t = edge.times[100] + 10;  // speed there ~ 2000 px/s, 10x the estimate
  auto thickness = [&](bool thinning) {
    ActiveEventMap set(kSensor, thinning);
    std::size_t next = 0;
    feed_until(edge.events, next, t, set);
    return active_columns(set, 40, t);
  };
  const auto thin = thickness(true);
  const auto thick = thickness(false);
  ASSERT_GE(thin.size(), 1u);
  EXPECT_LE(thin.size(), 2u);
  EXPECT_EQ(thin.back(), 100);  // the edge, not its trail
  EXPECT_GE(thick.size(), 5u) << "without thinning the overestimated lifetimes must smear";
}

TEST(ActiveEventMap, EdgeThinningOnlyExpiresTheSamePolarityBehindTheEdge) {
  ActiveEventMap set(kSensor, true);
  auto ev = [](std::int64_t t, int x, int y, int p, float vx, float vy) {
    AugmentedEvent a;
    a.event = Event{t, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), static_cast<std::int8_t>(p)};
    a.lifetime_us = 10000.0f;
    a.vx_px_s = vx;
    a.vy_px_s = vy;
    return a;
  };
  set.feed(ev(100, 10, 10, 1, 0, 0));    // behind, same polarity
  set.feed(ev(100, 20, 20, -1, 0, 0));   // behind, other polarity
  set.feed(ev(100, 31, 30, 1, 0, 0));    // ahead: must stay
  set.feed(ev(200, 11, 11, 1, 500, 500));   // moving down-right: behind = (10, 10)
  set.feed(ev(200, 21, 20, 1, 500, 0));     // moving right: behind = (20, 20), other polarity
  set.feed(ev(200, 30, 30, 1, 500, 0));     // moving right: behind = (29, 30), nothing there
  EXPECT_FALSE(set.is_active(10, 10, 300));
  EXPECT_TRUE(set.is_active(20, 20, 300));
  EXPECT_TRUE(set.is_active(31, 30, 300));
  EXPECT_TRUE(set.is_active(11, 11, 300));
  EXPECT_EQ(set.stats().thinned, 1u);
}

TEST(ActiveEventMap, NoiseIsNeverDrawn) {
  const auto times = constant_speed_times(500.0);
  auto events = moving_edge(times, [](int) { return 2000.0f; }, 500.0f);
  std::mt19937 rng(7);
  std::vector<AugmentedEvent> noise;
  for (int i = 0; i < 3000; ++i) {
    AugmentedEvent a;
    a.event = Event{kT0 + static_cast<std::int64_t>(rng() % 250000), static_cast<std::uint16_t>(rng() % 128),
                    static_cast<std::uint16_t>(rng() % 96), static_cast<std::int8_t>(rng() % 2 ? 1 : -1)};
    a.lifetime_us = 0.0f;  // the estimator's verdict: noise
    noise.push_back(a);
  }
  // Noise alone: nothing is ever active, nothing painted.
  ActiveEventMap set(kSensor);
  std::sort(noise.begin(), noise.end(), [](auto& a, auto& b) { return a.event.t_us < b.event.t_us; });
  std::size_t next = 0;
  cv::Mat img;
  const evlife::render::LifetimeColormap cmap;
  for (std::int64_t t = kT0; t < kT0 + 260000; t += 9973) {
    feed_until(noise, next, t, set);
    EXPECT_EQ(set.count_active(t), 0u);
    evlife::render::paint_active(set, t, evlife::render::ColorMode::plain, cmap, img);
    EXPECT_EQ(cv::countNonZero(img.reshape(1)), 0);
  }
  EXPECT_EQ(set.stats().noise, noise.size());
  // Mixed with an edge: every active pixel is on the edge's column.
  events.insert(events.end(), noise.begin(), noise.end());
  std::stable_sort(events.begin(), events.end(), [](auto& a, auto& b) { return a.event.t_us < b.event.t_us; });
  ActiveEventMap mixed(kSensor);
  next = 0;
  for (std::int64_t t = kT0 + 1001; t < kT0 + 250000; t += 12347) {
    feed_until(events, next, t, mixed);
    const double edge_x = static_cast<double>(t - kT0) * 500.0 / 1e6;
    for (int y = 0; y < kSensor.height; ++y)
      for (int c : active_columns(mixed, y, t)) ASSERT_NEAR(c, edge_x, 1.0) << "t=" << t << " y=" << y;
  }
}

TEST(ActiveEventMap, OutOfSensorEventsAreCountedNotStored) {
  ActiveEventMap set(kSensor);
  AugmentedEvent a;
  a.event = Event{10, 500, 3, 1};
  a.lifetime_us = 100.0f;
  set.feed(a);
  EXPECT_EQ(set.stats().out_of_sensor, 1u);
  EXPECT_EQ(set.count_active(10), 0u);
  EXPECT_THROW(ActiveEventMap(SensorSize{0, 10}), std::invalid_argument);
}

// Reference built independently from the event list: pixel active at t when
// its latest event e (e.t <= t, not noise) has t < e.t + lifetime.
TEST(ActiveEventMap, SamplingAtArbitraryIncreasingTimesMatchesABruteForceReference) {
  std::mt19937 rng(42);
  std::vector<AugmentedEvent> events;
  std::int64_t t = kT0;
  for (int i = 0; i < 20000; ++i) {
    t += rng() % 40;
    AugmentedEvent a;
    a.event = Event{t, static_cast<std::uint16_t>(rng() % 128), static_cast<std::uint16_t>(rng() % 96), 1};
    a.lifetime_us = (rng() % 5 == 0) ? 0.0f : static_cast<float>(50 + rng() % 20000) + 0.25f;
    events.push_back(a);
  }
  ActiveEventMap set(kSensor, /*edge_thinning=*/false);
  std::size_t next = 0;
  std::int64_t sample_t = kT0;
  for (int k = 0; k < 40; ++k) {
    sample_t += 1 + static_cast<std::int64_t>(rng() % 30000);  // irregular, not frame multiples
    feed_until(events, next, sample_t, set);
    std::vector<std::int64_t> latest_t(kSensor.pixel_count(), INT64_MIN);
    std::vector<double> latest_l(kSensor.pixel_count(), 0.0);
    for (const auto& a : events) {
      if (a.event.t_us > sample_t || a.lifetime_us <= 0.0f) continue;
      const std::size_t i = a.event.y * 128u + a.event.x;
      latest_t[i] = a.event.t_us;
      latest_l[i] = static_cast<double>(a.lifetime_us);
    }
    std::size_t expected_active = 0;
    for (std::size_t i = 0; i < latest_t.size(); ++i) {
      const bool active = latest_t[i] != INT64_MIN &&
                          static_cast<double>(sample_t - latest_t[i]) < latest_l[i];
      expected_active += active ? 1 : 0;
      ASSERT_EQ(set.is_active(i, sample_t), active) << "pixel " << i << " t " << sample_t;
    }
    EXPECT_EQ(set.count_active(sample_t), expected_active);
  }
}

// Time is kept relative to a moving epoch in 32 bits: hours of recording
// must behave like seconds.
TEST(ActiveEventMap, HoursLongRecordingsKeepExactTiming) {
  ActiveEventMap set(kSensor);
  FixedWindowMap map(kSensor);
  const std::int64_t start = 5'000'000'000;  // 83 min after the sensor's zero
  for (std::int64_t k = 0; k < 800; ++k) {   // one event every 10 s for 2.2 h
    AugmentedEvent a;
    a.event = Event{start + k * 10'000'000, 3, 4, 1};
    a.lifetime_us = 5'000'000.0f;
    set.feed(a);
    map.feed(a);
    const std::int64_t t = a.event.t_us;
    ASSERT_TRUE(set.is_active(3, 4, t + 4'999'999)) << k;
    ASSERT_FALSE(set.is_active(3, 4, t + 5'000'000)) << k;
    ASSERT_TRUE(map.is_active(4 * 128 + 3, t + 30'000, 30'000)) << k;
    ASSERT_FALSE(map.is_active(4 * 128 + 3, t + 30'001, 30'000)) << k;
    ASSERT_EQ(set.count_active(t + 1), 1u);
  }
}

// An in-memory source for the cursor.
class VectorSource final : public evlife::render::AugmentedSource {
 public:
  explicit VectorSource(std::vector<AugmentedEvent> events) : events_(std::move(events)) {}
  std::size_t read(std::span<AugmentedEvent> out) override {
    const std::size_t n = std::min(out.size(), events_.size() - next_);
    std::copy_n(events_.begin() + static_cast<std::ptrdiff_t>(next_), n, out.begin());
    next_ += n;
    return n;
  }
  SensorSize sensor() const override { return kSensor; }
  std::string description() const override { return "vector"; }
  const evlife::LifetimeStats* estimator_stats() const override { return nullptr; }

 private:
  std::vector<AugmentedEvent> events_;
  std::size_t next_ = 0;
};

TEST(RenderCursor, AdvancingFeedsExactlyTheEventsUpToEachTime) {
  const auto events = moving_edge(constant_speed_times(300.0), [](int) { return 3333.3f; }, 300.0f);
  VectorSource source(events);
  ActiveEventMap set(kSensor);
  FixedWindowMap window(kSensor);
  evlife::render::RenderCursor cursor(source, set, &window, /*buffer_events=*/100);
  ASSERT_EQ(cursor.first_t_us(), kT0);
  std::int64_t t = kT0;
  for (int k = 0; k < 30; ++k) {
    t += 13001;
    cursor.advance_to(t);
    const auto fed = static_cast<std::size_t>(std::count_if(
        events.begin(), events.end(), [&](const AugmentedEvent& a) { return a.event.t_us <= t; }));
    ASSERT_EQ(cursor.events_fed(), fed);
  }
  EXPECT_THROW(cursor.advance_to(t - 1), std::invalid_argument);
  cursor.advance_to(INT64_MAX);
  EXPECT_TRUE(cursor.exhausted());
  EXPECT_EQ(cursor.events_fed(), events.size());
}

TEST(Painter, LongLifetimesRedShortBlueAndUpscaledFrameSize) {
  ActiveEventMap set(kSensor);
  auto ev = [](int x, float lifetime) {
    AugmentedEvent a;
    a.event = Event{100, static_cast<std::uint16_t>(x), 5, 1};
    a.lifetime_us = lifetime;
    return a;
  };
  set.feed(ev(3, 400.0f));    // short
  set.feed(ev(9, 25000.0f));  // long
  const evlife::render::LifetimeColormap cmap(300.0, 30000.0);
  cv::Mat img;
  evlife::render::paint_active(set, 200, evlife::render::ColorMode::lifetime, cmap, img);
  const cv::Vec3b shortc = img.at<cv::Vec3b>(5, 3), longc = img.at<cv::Vec3b>(5, 9);  // BGR
  EXPECT_GT(shortc[0], shortc[2]);
  EXPECT_GT(longc[2], longc[0]);
  EXPECT_EQ(img.at<cv::Vec3b>(0, 0), evlife::render::kBackground);

  evlife::render::FrameStyle style;
  style.scale = 4;
  evlife::render::FrameComposer composer(evlife::render::parse_view_mode("compare"), style, "compare");
  FixedWindowMap window(kSensor);
  const cv::Mat& frame = composer.compose(set, window, 200);
  EXPECT_EQ(frame.size(), composer.frame_size(kSensor));
  EXPECT_GE(frame.cols, 3 * 4 * kSensor.width);
  EXPECT_GE(frame.rows, 4 * kSensor.height);
  // The short event, upscaled x4, sits in the third panel.
  const int x_panel = 2 * (4 * kSensor.width + 4);
  int label_h = frame.rows - 4 * kSensor.height - 24;
  const cv::Vec3b up = frame.at<cv::Vec3b>(label_h + 5 * 4 + 2, x_panel + 3 * 4 + 1);
  EXPECT_EQ(up, shortc);
}

TEST(LifetimeColormap, FastBinAgreesWithTheExactLogScale) {
  const evlife::render::LifetimeColormap cmap(250.0, 40000.0);
  EXPECT_EQ(cmap.bin(250.0f), 0);
  EXPECT_EQ(cmap.bin(40000.0f), 255);
  EXPECT_EQ(cmap.bin(100.0f), 0);
  EXPECT_EQ(cmap.bin(1e6f), 255);
  EXPECT_EQ(cmap.fast_bin(0.0f), 0);
  EXPECT_EQ(cmap.fast_bin(1e9f), 255);
  // Geometric middle of the range: the middle of the scale.
  EXPECT_NEAR(cmap.bin(static_cast<float>(std::sqrt(250.0 * 40000.0))), 128, 1);
  for (int k = 0; k < 1000; ++k) {  // 1 us .. 1e6 us, log-spaced
    const auto l = static_cast<float>(std::pow(10.0, 6.0 * k / 1000.0));
    ASSERT_NEAR(cmap.fast_bin(l), cmap.bin(l), 1) << l;
  }
}

TEST(Histogram, BinsQuantilesAndCdf) {
  evlife::render::Histogram h(0.0, 200.0, 10);  // 0.2 ms bins up to 2 ms
  for (double v : {-1.0, 0.0, 199.9, 200.0, 450.0, 1999.0, 2000.0, 5000.0}) h.add(v);
  h.add(std::numeric_limits<double>::quiet_NaN());  // ignored
  EXPECT_EQ(h.total(), 8u);
  EXPECT_EQ(h.below(), 1u);
  EXPECT_EQ(h.above(), 2u);
  EXPECT_EQ(h.count(0), 2u);
  EXPECT_EQ(h.count(1), 1u);
  EXPECT_EQ(h.count(2), 1u);
  EXPECT_EQ(h.count(9), 1u);
  EXPECT_DOUBLE_EQ(h.cdf_at_bin_end(0), 3.0 / 8.0);  // -1, 0, 199.9
  EXPECT_DOUBLE_EQ(h.cdf_at_bin_end(9), 6.0 / 8.0);
  EXPECT_DOUBLE_EQ(h.quantile(0.5), 400.0);  // 4th of 8 sorted values (200) lies in bin 1: upper edge
  EXPECT_THROW(evlife::render::Histogram(0.0, 0.0, 3), std::invalid_argument);
}

TEST(Histogram, LogBinsPercentilesAndShares) {
  // 10 bins per decade over [1, 1e6): a bin spans a factor 10^0.1.
  auto h = evlife::render::Histogram::log_bins(1.0, 1e6, 10);
  EXPECT_TRUE(h.is_log());
  EXPECT_EQ(h.bins(), 60u);
  const std::vector<double> values{0.5, 1.5, 15.0, 150.0, 1500.0, 2e6};  // sorted
  for (double v : values) h.add(v);
  h.add(std::numeric_limits<double>::quiet_NaN());  // ignored
  EXPECT_EQ(h.total(), 6u);
  EXPECT_EQ(h.below(), 1u);
  EXPECT_EQ(h.above(), 1u);
  // Nearest rank: rank ceil(q * 6); the outer counts give the range's ends.
  EXPECT_DOUBLE_EQ(h.percentile(0.0), 1.0);   // rank 1: 0.5, below the range
  EXPECT_DOUBLE_EQ(h.percentile(1.0), 1e6);   // rank 6: 2e6, above it
  for (const auto& [q, v] : std::vector<std::pair<double, double>>{{0.3, 1.5}, {0.5, 15.0}, {0.6, 150.0}, {0.8, 1500.0}}) {
    const double p = h.percentile(q);
    EXPECT_GT(p, v / std::pow(10.0, 0.1)) << q;  // the centre of v's bin: within one bin of v
    EXPECT_LT(p, v * std::pow(10.0, 0.1)) << q;
  }
  const std::size_t k = static_cast<std::size_t>(std::floor(std::log10(15.0) * 10));  // 15's bin
  EXPECT_EQ(h.count(k), 1u);
  EXPECT_NEAR(h.bin_centre(k), std::sqrt(h.bin_start(k) * h.bin_start(k + 1)), 1e-9);
  EXPECT_DOUBLE_EQ(h.percentile(0.5), h.bin_centre(k));
  EXPECT_DOUBLE_EQ(h.share_below(1000.0), 4.0 / 6.0);  // 0.5, 1.5, 15, 150
  EXPECT_DOUBLE_EQ(h.share_below(0.9), 0.0);           // below lo: nothing counted yet
  EXPECT_DOUBLE_EQ(h.share_below(1e7), 5.0 / 6.0);     // all but the overflow
  EXPECT_THROW(evlife::render::Histogram::log_bins(0.0, 10.0, 10), std::invalid_argument);
  EXPECT_THROW(evlife::render::Histogram::log_bins(10.0, 1.0, 10), std::invalid_argument);
  EXPECT_THROW(evlife::render::Histogram::log_bins(1.0, 10.0, 0), std::invalid_argument);
}

TEST(Plot, DrawsTheRequestedSizeAndRejectsMismatchedSeries) {
  evlife::render::PlotOptions o;
  o.title = "t";
  o.x_label = "x [ms]";
  o.y_label = "y";
  o.width = 400;
  o.height = 300;
  evlife::render::PlotSeries s;
  s.label = "a";
  s.x = {0, 1, 2};
  s.y = {0, 1, 4};
  const cv::Mat img = evlife::render::draw_plot(o, {s});
  EXPECT_EQ(img.cols, 400);
  EXPECT_EQ(img.rows, 300);
  // The series colour appears (the curve is drawn).
  cv::Mat hits;
  cv::inRange(img, s.color - cv::Scalar(1, 1, 1), s.color + cv::Scalar(1, 1, 1), hits);
  EXPECT_GT(cv::countNonZero(hits), 50);
  s.y.pop_back();
  EXPECT_THROW(evlife::render::draw_plot(o, {s}), std::invalid_argument);
}

// A point without a value (NaN: eval's score where completeness has no
// reference) leaves a gap; the line was drawn across it as if it had one.
TEST(Plot, APointWithoutAValueIsAGapNotABridge) {
  evlife::render::PlotOptions o;
  o.width = 400;
  o.height = 300;
  o.y_min = 0.0;
  o.y_max = 1.0;
  evlife::render::PlotSeries s;
  s.label = "a";
  s.x = {0, 1, 2, 3, 4};
  s.y = {0.5, 0.5, 0.5, 0.5, 0.5};
  const auto drawn_px = [&](const evlife::render::PlotSeries& series) {
    cv::Mat hits;
    cv::inRange(evlife::render::draw_plot(o, {series}), series.color - cv::Scalar(1, 1, 1),
                series.color + cv::Scalar(1, 1, 1), hits);
    return cv::countNonZero(hits);
  };
  const int whole = drawn_px(s);
  s.y[2] = std::numeric_limits<double>::quiet_NaN();
  const int gapped = drawn_px(s);
  EXPECT_LT(gapped, whole - 100) << "the line from x = 1 to 3 is drawn: " << gapped << " of " << whole << " px";
  EXPECT_GT(gapped, 100);  // the runs on either side are
  s.y = {std::numeric_limits<double>::quiet_NaN(), 0.5, std::numeric_limits<double>::quiet_NaN(), 0.25,
         std::numeric_limits<double>::quiet_NaN()};
  const int legend_only = [&] {
    evlife::render::PlotSeries none = s;
    none.y.assign(5, std::numeric_limits<double>::quiet_NaN());
    return drawn_px(none);
  }();
  EXPECT_GT(drawn_px(s), legend_only) << "values between gaps are drawn (as dots)";
}

TEST(Parsing, DurationsAndModes) {
  using evlife::render::parse_duration_us;
  EXPECT_EQ(parse_duration_us("30ms"), 30000);
  EXPECT_EQ(parse_duration_us("250us"), 250);
  EXPECT_EQ(parse_duration_us("0.25s"), 250000);
  EXPECT_EQ(parse_duration_us("1.5"), 1500000);
  EXPECT_THROW(parse_duration_us("3 ms"), std::invalid_argument);
  EXPECT_THROW(parse_duration_us("-1ms"), std::invalid_argument);
  EXPECT_THROW(parse_duration_us("ms"), std::invalid_argument);
  const auto compare = evlife::render::parse_view_mode("compare");
  ASSERT_EQ(compare.size(), 3u);
  EXPECT_EQ(compare[0].window_us, 1000);
  EXPECT_EQ(compare[1].window_us, 30000);
  EXPECT_TRUE(compare[2].lifetime);
  EXPECT_EQ(evlife::render::parse_view_mode("window:5ms").at(0).window_us, 5000);
  EXPECT_THROW(evlife::render::parse_view_mode("window:"), std::invalid_argument);
  EXPECT_THROW(evlife::render::parse_view_mode("blur"), std::invalid_argument);
}

TEST(Sharpness, ThinLinesCountThickBandsAndDotsDoNot) {
  cv::Mat mask(64, 64, CV_8UC1, cv::Scalar(0));
  mask.col(10).setTo(255);                             // 1 px line, 64 px long
  mask(cv::Rect(30, 0, 12, 64)).setTo(255);            // 12 px band
  mask.at<std::uint8_t>(5, 55) = 255;                  // isolated dot
  const auto s = evlife::render::measure_sharpness(mask);
  EXPECT_EQ(s.active_pixels, 64u + 12u * 64u + 1u);
  EXPECT_EQ(s.thin_edge_pixels, 64u);
  EXPECT_EQ(s.edge_pixels, 64u + 12u * 64u);
  EXPECT_NEAR(s.thin_edge_share(), 64.0 / (64 + 768 + 1), 1e-9);
  cv::Mat diag(32, 32, CV_8UC1, cv::Scalar(0));
  for (int i = 0; i < 32; ++i) diag.at<std::uint8_t>(i, i) = 255;
  EXPECT_DOUBLE_EQ(evlife::render::measure_sharpness(diag).thin_edge_share(), 1.0);
}

// --to T at F fps draws every frame k with from + k / F <= T, the last one at
// T itself when T is on the frame grid (0.2 s at 10 fps: 1e-6 * 200000 * 10
// is 1.9999999999999998, which floored to one frame short).
TEST(FrameClock, CountThroughIncludesTheLastInstantOnTheGrid) {
  using evlife::render::frame_count_through;
  using evlife::render::frame_instant_us;
  EXPECT_EQ(frame_count_through(0, 200000, 10.0), 3u);
  EXPECT_EQ(frame_count_through(0, 199999, 10.0), 2u);
  EXPECT_EQ(frame_count_through(0, 0, 30.0), 1u);
  EXPECT_EQ(frame_count_through(5, 4, 30.0), 0u);
  for (const double fps : {1.0, 7.0, 10.0, 29.97, 30.0, 60.0, 1000.0}) {
    for (std::int64_t from : {0, 123, 1000000}) {
      for (std::int64_t span : {0, 1, 33333, 200000, 1000000, 2345678}) {
        const auto n = frame_count_through(from, from + span, fps);
        ASSERT_GE(n, 1u);
        EXPECT_LE(frame_instant_us(from, n - 1, fps), from + span) << fps << " " << from << " " << span;
        EXPECT_GT(frame_instant_us(from, n, fps), from + span) << fps << " " << from << " " << span;
      }
    }
  }
}

// Instants past the clock's end are none (INT64_MAX, never reached): counts
// up to 2^63 - 1 us end, from either end of the clock (they looped for ever:
// an instant wrapped to INT64_MIN).
TEST(FrameClock, CountsEndAtTheEndOfTheClock) {
  using evlife::render::clock_span_us;
  using evlife::render::frame_count_through;
  using evlife::render::frame_instant_us;
  EXPECT_EQ(frame_instant_us(INT64_MAX - 10, 1, 30.0), INT64_MAX);
  EXPECT_EQ(frame_instant_us(0, std::uint64_t{1} << 62, 1e-3), INT64_MAX);
  EXPECT_EQ(clock_span_us(INT64_MIN, INT64_MAX), INT64_MAX);
  EXPECT_EQ(clock_span_us(-5, 5), 10);
  const std::uint64_t all = frame_count_through(0, INT64_MAX, 30.0);  // ~2.8e14 frames
  EXPECT_NEAR(static_cast<double>(all), 9.223372036854775807e18 * 30.0 / 1e6, 1e3);
  EXPECT_LE(frame_instant_us(0, all - 1, 30.0), INT64_MAX - 1);
  EXPECT_EQ(frame_count_through(INT64_MAX, INT64_MAX, 30.0), 1u);  // frame 0 at the last instant
  EXPECT_EQ(frame_count_through(INT64_MIN, INT64_MIN + 1, 30.0), 1u);
}

// The video's codec follows the extension whatever its case (.MP4 asked
// OpenCV for MJPG in an MP4 container: a fallback warning, twice).
TEST(OutputKind, VideoExtensionsInAnyCaseNameTheirCodec) {
  using evlife::render::OutputKind;
  for (const char* mp4 : {"v.mp4", "dir/V.MP4", "v.Mp4"}) {
    EXPECT_EQ(evlife::render::output_kind(mp4), OutputKind::video) << mp4;
    EXPECT_STREQ(evlife::render::video_codec(mp4), "mp4v") << mp4;
  }
  for (const char* avi : {"v.avi", "V.AVI"}) EXPECT_STREQ(evlife::render::video_codec(avi), "MJPG") << avi;
}

}  // namespace
