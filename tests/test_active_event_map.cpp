// The active-event map (algo/include/evlife/algo/active_event_map.h) alone:
// edge thinning as the paper states it (III-B.3: a new event with velocity v
// expires the same-polarity event at the neighbour in -v direction) and the
// queries that hand the edge image to flight software. Links evlife::algo
// only; built without exceptions in .ci/algo-no-exceptions. Moving edges and
// the rendering side: test_render.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "evlife/algo/active_event_map.h"

namespace evlife {
namespace {

constexpr SensorSize kSensor{32, 24};

AugmentedEvent at(int x, int y, std::int64_t t_us, int polarity, float lifetime_us, float vx,
                  float vy) {
  return {Event{t_us, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y),
                static_cast<std::int8_t>(polarity)},
          lifetime_us, vx, vy};
}

// An old event at (15, 10), then a new one at its neighbour (15+dx, 10+dy)
// moving with velocity angle `deg`: is the old one still active?
bool old_survives(int dx, int dy, double deg, int old_polarity = 1, bool thinning = true) {
  ActiveEventMap map(kSensor, thinning);
  map.feed(at(15, 10, 1000, old_polarity, 10000.0f, 0.0f, 0.0f));
  const double r = deg * 3.14159265358979 / 180.0;
  map.feed(at(15 + dx, 10 + dy, 2000, 1, 10000.0f, static_cast<float>(500.0 * std::cos(r)),
              static_cast<float>(500.0 * std::sin(r))));
  return map.is_active(15, 10, 2000);
}

TEST(ActiveEventMap, ThinningExpiresOnlyTheSamePolarityPixelTheEdgeHasJustLeft) {
  // Each of the 8 sectors of 45 degrees points at one neighbour: the event
  // behind the new one (at -v) is expired, whatever the sector.
  for (int k = 0; k < 8; ++k) {
    const double deg = 45.0 * k;
    const int dx = static_cast<int>(std::lround(std::cos(deg * 3.14159265358979 / 180.0)));
    const int dy = static_cast<int>(std::lround(std::sin(deg * 3.14159265358979 / 180.0)));
    SCOPED_TRACE(deg);
    EXPECT_FALSE(old_survives(dx, dy, deg));            // behind the edge: expired
    EXPECT_FALSE(old_survives(dx, dy, deg + 20.0));     // inside the same sector
    EXPECT_TRUE(old_survives(dx, dy, deg + 25.0));      // next sector: another neighbour
    EXPECT_TRUE(old_survives(-dx, -dy, deg));           // ahead of the edge: kept
    EXPECT_TRUE(old_survives(dx, dy, deg, -1));         // other polarity: kept
    EXPECT_TRUE(old_survives(dx, dy, deg, 1, false));   // thinning off: kept
  }
}

TEST(ActiveEventMap, ThinningNeverTouchesNewerOrExpiredNeighboursAndIsCounted) {
  ActiveEventMap map(kSensor);
  // Neighbour newer than the thinning event (a late arrival at this pixel).
  map.feed(at(4, 4, 5000, 1, 1000.0f, 0.0f, 0.0f));
  map.feed(at(5, 4, 5000, 1, 1000.0f, 800.0f, 0.0f));  // same time: not older
  EXPECT_TRUE(map.is_active(4, 4, 5000));
  // Neighbour already expired: nothing to thin.
  map.feed(at(10, 4, 1000, 1, 100.0f, 0.0f, 0.0f));
  map.feed(at(11, 4, 5000, 1, 1000.0f, 800.0f, 0.0f));
  EXPECT_EQ(map.stats().thinned, 0u);
  // A zero or non-finite velocity points nowhere.
  map.feed(at(20, 4, 1000, 1, 9000.0f, 0.0f, 0.0f));
  map.feed(at(21, 4, 5000, 1, 1000.0f, 0.0f, 0.0f));
  map.feed(at(21, 4, 5001, 1, 1000.0f, INFINITY, 0.0f));
  EXPECT_TRUE(map.is_active(20, 4, 5001));
  map.feed(at(21, 4, 5002, 1, 1000.0f, 800.0f, 0.0f));
  EXPECT_FALSE(map.is_active(20, 4, 5002));
  EXPECT_EQ(map.stats().thinned, 1u);
  // The thinned pixel keeps its data; only its expiry moved to now.
  EXPECT_EQ(map.t_us(map.sensor().width * 4 + 20), 1000);
}

TEST(ActiveEventMap, QueriesReturnTheActivePixelsWithTheirData) {
  ActiveEventMap map(kSensor, /*edge_thinning=*/false);
  map.feed(at(3, 2, 100, 1, 500.0f, 10.0f, 20.0f));     // active until 600
  map.feed(at(30, 2, 200, -1, 1000.5f, -5.0f, 0.0f));  // until 1201 (ceil)
  map.feed(at(7, 20, 300, 1, 0.0f, 0.0f, 0.0f));       // noise: never active
  map.feed(at(1, 23, 400, 1, 2000.0f, 1.0f, 2.0f));    // until 2400
  std::vector<ActivePixel> out(8);
  ASSERT_EQ(map.active_pixels(599, out), 3u);
  EXPECT_EQ(out[0].x, 3);  // row-major order
  EXPECT_EQ(out[0].y, 2);
  EXPECT_EQ(out[0].t_us, 100);
  EXPECT_EQ(out[0].lifetime_us, 500.0f);
  EXPECT_EQ(out[0].vx_px_s, 10.0f);
  EXPECT_EQ(out[0].vy_px_s, 20.0f);
  EXPECT_EQ(out[1].x, 30);
  EXPECT_EQ(out[1].polarity, -1);
  EXPECT_EQ(out[2].y, 23);
  EXPECT_EQ(map.active_pixels(600, out), 2u);
  EXPECT_EQ(map.active_pixels(1200, out), 2u);
  EXPECT_EQ(map.active_pixels(1201, out), 1u);
  // A short buffer gets the first pixels; the count says how many there are.
  std::vector<ActivePixel> one(1);
  EXPECT_EQ(map.active_pixels(599, one), 3u);
  EXPECT_EQ(one[0].x, 3);

  std::vector<float> image(static_cast<std::size_t>(kSensor.pixel_count()), -1.0f);
  map.lifetime_image(1000, image);
  std::size_t nonzero = 0;
  for (std::size_t i = 0; i < image.size(); ++i) {
    EXPECT_EQ(image[i] != 0.0f, map.is_active(i, 1000)) << i;
    nonzero += image[i] != 0.0f;
  }
  EXPECT_EQ(nonzero, map.count_active(1000));
  EXPECT_EQ(image[2 * 32 + 30], 1000.5f);
  EXPECT_EQ(image[23 * 32 + 1], 2000.0f);
}

// Times far apart are compared without overflow: a query at the end of time
// finds nothing active (it found the event of 100 us at t = 0: the difference
// wrapped), an event ~71 min before the map's newest, at a pixel that never
// fired, is counted late (its expiry wrapped into a ghost active for ever),
// and times beyond +-2^62 us are counted and ignored.
TEST(ActiveEventMap, TimesFarApartNeitherWrapNorLeaveGhosts) {
  ActiveEventMap map(kSensor);
  map.feed(at(0, 0, 0, 1, 100.0f, 0.0f, 0.0f));
  EXPECT_EQ(map.count_active(0), 1u);
  EXPECT_EQ(map.count_active(std::numeric_limits<std::int64_t>::max()), 0u);

  const std::int64_t now = std::int64_t{1} << 30;
  map.feed(at(2, 2, now, 1, 100.0f, 0.0f, 0.0f));
  map.feed(at(1, 1, now - (std::int64_t{1} << 32), 1, 100.0f, 0.0f, 0.0f));
  EXPECT_FALSE(map.is_active(1, 1, now + 50));
  EXPECT_EQ(map.stats().late, 1u);

  map.feed(at(3, 3, std::numeric_limits<std::int64_t>::min(), 1, 100.0f, 0.0f, 0.0f));
  map.feed(at(3, 3, kMaxEventTimeUs + 1, 1, 100.0f, 0.0f, 0.0f));
  EXPECT_EQ(map.stats().time_out_of_range, 2u);
  EXPECT_FALSE(map.is_active(3, 3, kMaxEventTimeUs + 1));
  EXPECT_EQ(map.count_active(now + 50), 1u);  // (2, 2) only
}

// Times at both ends of event.h's range (2^63 apart): no signed overflow
// (UBSan) and the later event is active, not counted late.
TEST(ActiveEventMap, TimesAtBothEndsOfTheRangeAreFedWithoutOverflow) {
  ActiveEventMap map(kSensor);
  map.feed(at(0, 0, -kMaxEventTimeUs, 1, 100.0f, 0.0f, 0.0f));
  map.feed(at(1, 1, kMaxEventTimeUs, 1, 100.0f, 0.0f, 0.0f));
  EXPECT_EQ(map.stats().late, 0u);
  EXPECT_TRUE(map.is_active(1, 1, kMaxEventTimeUs));
  EXPECT_FALSE(map.is_active(0, 0, kMaxEventTimeUs));
  map.feed(at(2, 2, -kMaxEventTimeUs, 1, 100.0f, 0.0f, 0.0f));  // 2^63 before the epoch now: late
  EXPECT_EQ(map.stats().late, 1u);
}

// Moved from, a map has no planes: feed() counts every event out of the
// sensor, its sensor is 0 x 0 and it counts nothing active (feed() read past
// the emptied arrays).
TEST(ActiveEventMap, AMovedFromMapReadsNothing) {
  ActiveEventMap a(kSensor);
  ActiveEventMap b(std::move(a));
  a.feed(at(1, 1, 1000, 1, 100.0f, 0.0f, 0.0f));  // NOLINT(bugprone-use-after-move): the point
  EXPECT_EQ(a.stats().out_of_sensor, 1u);
  EXPECT_EQ(a.sensor().pixel_count(), 0);  // (is_active asks for a pixel inside sensor())
  EXPECT_EQ(a.count_active(1000), 0u);
  b.feed(at(1, 1, 1000, 1, 100.0f, 0.0f, 0.0f));
  EXPECT_TRUE(b.is_active(1, 1, 1000));
}

TEST(ActiveEventMap, FitsNamesTheSensorsTheConstructorAccepts) {
  EXPECT_TRUE(ActiveEventMap::fits({1, 1}));
  EXPECT_TRUE(ActiveEventMap::fits({1280, 720}));
  EXPECT_FALSE(ActiveEventMap::fits({0, 10}));
  EXPECT_FALSE(ActiveEventMap::fits({10, -1}));
  EXPECT_FALSE(ActiveEventMap::fits({ActiveEventMap::kMaxSide + 1, 10}));
}

}  // namespace
}  // namespace evlife
