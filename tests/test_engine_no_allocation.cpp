// Proves that the engine's stages allocate nothing and take no lock per
// event once built: malloc & co., operator new and pthread_mutex_lock are
// interposed and counted while the stages run a whole recording (stepped
// inline, as the threads step them). Skipped under sanitizers, which
// interpose the allocator themselves.
#include <gtest/gtest.h>

#if !defined(__SANITIZE_THREAD__) && !defined(__SANITIZE_ADDRESS__)
#include <dlfcn.h>
#include <pthread.h>

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <new>
#include <string>
#include <vector>

#include "evlife/engine/pipeline.h"
#include "evlife/engine/replay_source.h"
#include "evlife/io/event_reader.h"

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
}  // extern "C"

void* operator new(std::size_t n) {
  note_allocation();
  if (void* p = __libc_malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace ee = evlife::engine;

namespace {
std::vector<evlife::Event> stripes() {
  auto reader = evlife::io::open_event_reader(std::string(EVLIFE_SHARED_DATA_DIR) +
                                              "/reference/stripes.mat");
  std::vector<evlife::Event> events(100'000);
  std::size_t n = 0;
  while (n < events.size()) {
    const std::size_t got = reader->read(std::span(events.data() + n, events.size() - n));
    if (got == 0) break;
    n += got;
  }
  events.resize(n);
  return events;
}

void expect_no_allocation(ee::OverloadPolicy policy, int tiles, bool render_tap) {
  const auto events = stripes();
  ee::ReplaySource source(events, {128, 128});
  ee::EngineOptions o;
  o.lifetime.sensor = {128, 128};
  o.workers = 3;
  o.tiles_x = tiles;
  o.tiles_y = tiles;
  o.batch_events = 128;
  o.batches_per_worker = 4;
  o.auto_policy = false;
  o.policy = policy;
  o.render_batches = render_tap ? 2 : 0;
  ee::Pipeline pipeline(source, nullptr, o);
  g_allocations = 0;
  g_locks = 0;
  g_armed = true;
  // The order in which threads would interleave does not matter; starve the
  // merger now and then so that pools fill and the overload paths run too.
  for (int i = 0; !pipeline.state().input_done.load() || pipeline.merger().step() != ee::StepResult::finished; ++i) {
    pipeline.router().step();
    for (int w = 0; w < pipeline.worker_count(); ++w) pipeline.worker(w).step();
    if (i % 7 < 5) pipeline.merger().step();
    if (render_tap && i % 3 == 0) {
      if (ee::RenderBatch* b = pipeline.state().render_tap->try_take()) pipeline.state().render_tap->give_back(b);
    }
  }
  g_armed = false;
  const auto st = pipeline.stats();
  EXPECT_EQ(st.events_in, events.size());
  EXPECT_EQ(st.events_in, st.events_out + st.events_dropped);
  if (policy == ee::OverloadPolicy::drop) {
    EXPECT_GT(st.events_dropped, 0u);
  }
  EXPECT_EQ(g_allocations.load(), 0) << "allocations while the stages ran";
  EXPECT_EQ(g_locks.load(), 0) << "mutex locks while the stages ran";
}
}  // namespace

TEST(EngineNoAllocation, BlockPolicyTiledWithRenderTap) {
  expect_no_allocation(ee::OverloadPolicy::block, 2, true);
}
TEST(EngineNoAllocation, DropPolicyTiled) { expect_no_allocation(ee::OverloadPolicy::drop, 2, false); }
TEST(EngineNoAllocation, DropPolicyRenderTapPerPolarity) {
  expect_no_allocation(ee::OverloadPolicy::drop, 1, true);
}

#else
TEST(EngineNoAllocation, SkippedUnderSanitizers) { GTEST_SKIP() << "sanitizers interpose the allocator"; }
#endif
