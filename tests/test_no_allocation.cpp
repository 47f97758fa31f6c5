// Proves that the per-event path allocates nothing and takes no lock: the
// allocation probe (tests/probe) interposes malloc & co., operator new and
// pthread_mutex_lock and counts calls made while it is armed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <vector>

#include "allocation_probe.h"
#include "evlife/algo/active_event_map.h"
#include "evlife/algo/lifetime_estimator.h"

namespace evlife {
namespace {

using test::AllocationProbe;

// Edges, noise, border pixels, out-of-sensor and bad-polarity events, with
// and without regularization, for every window size: every branch of process().
std::vector<Event> mixed_events(SensorSize s) {
  std::vector<Event> ev;
  std::uint32_t r = 7;
  for (int pass = 0; pass < 3; ++pass) {
    for (int x = 0; x < s.width; ++x) {
      for (int y = 0; y < s.height; ++y) {
        const std::int64_t t = pass * 200000 + x * 1000 + (y * 37) % 50;
        ev.push_back({t, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y),
                      pass % 2 ? std::int8_t{-1} : std::int8_t{1}});
      }
      r = r * 1664525u + 1013904223u;
      ev.push_back({pass * 200000 + x * 1000 + 500, static_cast<std::uint16_t>(r % (s.width + 3)),
                    static_cast<std::uint16_t>((r >> 10) % (s.height + 3)),
                    static_cast<std::int8_t>(static_cast<int>((r >> 20) % 3) - 1)});
    }
  }
  std::stable_sort(ev.begin(), ev.end(), [](const Event& a, const Event& b) { return a.t_us < b.t_us; });
  return ev;
}

TEST(NoAllocation, InterpositionIsActive) {
  if (!test::allocation_probe_available()) GTEST_SKIP() << "sanitizers interpose the allocator";
  // The probe must see an allocation, or the tests below prove nothing.
  AllocationProbe probe;
  std::vector<int>* v = new std::vector<int>(100);  // 1 or 2 (the optimizer may merge new-expressions)
  void* volatile n = ::operator new(16);             // a call, not a new-expression: never merged
  void* volatile m = std::malloc(10);                // volatile: not elided
  probe.disarm();
  delete v;
  ::operator delete(n);
  std::free(m);
  EXPECT_GE(probe.allocations(), 3);
}

TEST(NoAllocation, PerEventPathAllocatesNothingAndTakesNoLock) {
  if (!test::allocation_probe_available()) GTEST_SKIP() << "sanitizers interpose the allocator";
  const SensorSize s{40, 30};
  auto events = mixed_events(s);
  events.push_back({0, 1, 1, 1});  // and time going backwards (rejected)
  for (int window : {3, 5, 7, 15}) {
    for (bool reg : {false, true}) {
      LifetimeOptions o;
      o.sensor = s;
      o.window_size = window;
      o.regularization = reg;
      // The opt-in checks too (their paths run only when on).
      o.burst_span_timing_noise = reg ? 10.0 : 0.0;
      o.max_event_offset_tolerances = reg ? 2.0 : 0.0;
      o.late_event_keeps_arrival_timing_noise = reg ? 15.0 : 0.0;  // config/dim-light.yaml's
      o.late_follower_upstream_durations = reg ? 1.5 : 0.0;
      LifetimeEstimator est(o);  // allocates here, at construction
      std::vector<AugmentedEvent> out(events.size());
      long edges = 0;
      AllocationProbe probe;
      for (std::size_t i = 0; i < events.size() / 2; ++i) out[i] = est.process(events[i]);
      est.process(std::span<const Event>(events).subspan(events.size() / 2),
                  std::span<AugmentedEvent>(out).subspan(events.size() / 2));
      probe.disarm();
      for (const auto& a : out) edges += !a.is_noise();
      EXPECT_EQ(probe.allocations(), 0) << "window " << window << " reg and opt-in checks " << reg;
      EXPECT_EQ(probe.locks(), 0) << "window " << window << " reg and opt-in checks " << reg;
      EXPECT_GT(edges, static_cast<long>(events.size()) / 4);  // the fit path did run
      EXPECT_EQ(est.stats().time_backwards, 1u);
    }
  }
}

// The active-event map (algo/include/evlife/algo/active_event_map.h) after its
// construction: feed() on every branch (stored, noise, out of sensor, late,
// thinned, an epoch rebase after ~10 minutes), the queries and reset().
// state_bytes() is what the constructor allocates, byte for byte (callers
// weigh it against their memory; with mlockall all of it is resident): it
// left out the planes' rounding to 2 MiB pages and the RANSAC table (3.5 MB
// for 5.2 MB at 240 x 180).
TEST(NoAllocation, StateBytesIsWhatTheConstructorAllocates) {
  if (!test::allocation_probe_available()) GTEST_SKIP() << "built with a sanitizer";
  for (const SensorSize sensor : {SensorSize{128, 128}, SensorSize{240, 180}, SensorSize{346, 260}, SensorSize{1280, 720}}) {
    LifetimeOptions o;
    o.sensor = sensor;
    test::AllocationProbe probe;
    const LifetimeEstimator estimator(o);
    probe.disarm();
    EXPECT_EQ(probe.bytes(), LifetimeEstimator::state_bytes(sensor)) << sensor.width << "x" << sensor.height;
  }
}

TEST(NoAllocation, ActiveEventMapFeedAndQueriesAllocateNothing) {
  if (!test::allocation_probe_available()) GTEST_SKIP() << "sanitizers interpose the allocator";
  const SensorSize s{40, 30};
  const auto raw = mixed_events(s);
  std::vector<AugmentedEvent> events;
  for (std::size_t i = 0; i < raw.size(); ++i) {
    const float lifetime = i % 7 == 0 ? 0.0f : 1000.0f + static_cast<float>(i % 13) * 100.0f;
    events.push_back({raw[i], lifetime, 900.0f, static_cast<float>(i % 5) * 300.0f - 600.0f});
  }
  AugmentedEvent far_later{raw[0], 5000.0f, 0.0f, 0.0f};
  far_later.event.t_us = std::int64_t{600} * 1000000;  // past the int32 range of the epoch
  for (bool thinning : {false, true}) {
    ActiveEventMap map(s, thinning);  // allocates here, at construction
    std::vector<ActivePixel> pixels(static_cast<std::size_t>(s.pixel_count()));
    std::vector<float> image(static_cast<std::size_t>(s.pixel_count()));
    AllocationProbe probe;
    map.feed(std::span<const AugmentedEvent>(events).first(events.size() / 2));
    for (std::size_t i = events.size() / 2; i < events.size(); ++i) map.feed(events[i]);
    map.feed(events[1]);  // late (events[0] is noise)
    const std::int64_t t = events.back().event.t_us;
    const std::size_t active = map.count_active(t) + map.active_pixels(t, pixels);
    map.lifetime_image(t, image);
    map.feed(far_later);
    const std::size_t after_rebase = map.active_pixels(far_later.event.t_us, pixels);
    const ActiveEventMapStats seen = map.stats();
    map.reset();
    probe.disarm();
    EXPECT_EQ(probe.allocations(), 0) << "thinning " << thinning;
    EXPECT_EQ(probe.locks(), 0) << "thinning " << thinning;
    EXPECT_GT(active, 0u);  // the queries did find active pixels
    EXPECT_EQ(after_rebase, 1u);
    EXPECT_GT(seen.noise, 0u);  // every branch of feed() ran
    EXPECT_GT(seen.out_of_sensor, 0u);
    EXPECT_EQ(seen.late, 1u);
    if (thinning) {
      EXPECT_GT(seen.thinned, 0u);
    }
  }
}

}  // namespace
}  // namespace evlife
