// Proves that the per-event path allocates nothing and takes no lock: this
// binary interposes malloc/calloc/realloc/aligned allocation, operator new
// and pthread_mutex_lock, and counts calls made while a probe is armed.
#include <gtest/gtest.h>
#include <pthread.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <dlfcn.h>
#include <new>
#include <vector>

#include "evlife/algo/lifetime_estimator.h"

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
}

namespace {
std::atomic<bool> g_armed{false};
std::atomic<long> g_allocations{0};
std::atomic<long> g_locks{0};

void note_allocation() {
  if (g_armed.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
}
}  // namespace

extern "C" {
void* malloc(std::size_t n) {
  note_allocation();
  return __libc_malloc(n);
}
void* calloc(std::size_t a, std::size_t b) {
  note_allocation();
  return __libc_calloc(a, b);
}
void* realloc(void* p, std::size_t n) {
  note_allocation();
  return __libc_realloc(p, n);
}
int posix_memalign(void** out, std::size_t align, std::size_t n) {
  note_allocation();
  *out = __libc_memalign(align, n);
  return *out ? 0 : ENOMEM;
}
void* aligned_alloc(std::size_t align, std::size_t n) {
  note_allocation();
  return __libc_memalign(align, n);
}
int pthread_mutex_lock(pthread_mutex_t* m) {
  if (g_armed.load(std::memory_order_relaxed)) g_locks.fetch_add(1, std::memory_order_relaxed);
  using Fn = int (*)(pthread_mutex_t*);
  static Fn real = reinterpret_cast<Fn>(dlsym(RTLD_NEXT, "pthread_mutex_lock"));
  return real(m);
}
}

void* operator new(std::size_t n) {
  note_allocation();
  if (void* p = __libc_malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace evlife {
namespace {

struct Probe {
  Probe() {
    g_allocations = 0;
    g_locks = 0;
    g_armed = true;
  }
  ~Probe() { g_armed = false; }
};

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
  // The probe must see an allocation, or the tests below prove nothing.
  Probe probe;
  std::vector<int>* v = new std::vector<int>(100);
  void* m = std::malloc(10);
  g_armed = false;
  delete v;
  std::free(m);
  EXPECT_GE(g_allocations.load(), 3);
}

TEST(NoAllocation, PerEventPathAllocatesNothingAndTakesNoLock) {
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
      {
        Probe probe;
        for (std::size_t i = 0; i < events.size() / 2; ++i) out[i] = est.process(events[i]);
        est.process(std::span<const Event>(events).subspan(events.size() / 2),
                    std::span<AugmentedEvent>(out).subspan(events.size() / 2));
      }
      for (const auto& a : out) edges += !a.is_noise();
      EXPECT_EQ(g_allocations.load(), 0) << "window " << window << " reg " << reg;
      EXPECT_EQ(g_locks.load(), 0) << "window " << window << " reg " << reg;
      EXPECT_GT(edges, static_cast<long>(events.size()) / 4);  // the fit path did run
    }
  }
}

}  // namespace
}  // namespace evlife
