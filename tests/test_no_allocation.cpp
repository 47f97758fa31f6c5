// Proves that the per-event path allocates nothing and takes no lock: the
// allocation probe (tests/probe) interposes malloc & co., operator new and
// pthread_mutex_lock and counts calls made while it is armed.
#include <gtest/gtest.h>

#include <cstdlib>
#include <vector>

#include "allocation_probe.h"
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
  const auto events = mixed_events(s);
  for (int window : {3, 5, 7, 15}) {
    for (bool reg : {false, true}) {
      LifetimeOptions o;
      o.sensor = s;
      o.window_size = window;
      o.regularization = reg;
      LifetimeEstimator est(o);  // allocates here, at construction
      std::vector<AugmentedEvent> out(events.size());
      long edges = 0;
      AllocationProbe probe;
      for (std::size_t i = 0; i < events.size() / 2; ++i) out[i] = est.process(events[i]);
      est.process(std::span<const Event>(events).subspan(events.size() / 2),
                  std::span<AugmentedEvent>(out).subspan(events.size() / 2));
      probe.disarm();
      for (const auto& a : out) edges += !a.is_noise();
      EXPECT_EQ(probe.allocations(), 0) << "window " << window << " reg " << reg;
      EXPECT_EQ(probe.locks(), 0) << "window " << window << " reg " << reg;
      EXPECT_GT(edges, static_cast<long>(events.size()) / 4);  // the fit path did run
    }
  }
}

}  // namespace
}  // namespace evlife
