#include "allocation_probe.h"

#include <atomic>

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define EVLIFE_PROBE_DISABLED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define EVLIFE_PROBE_DISABLED 1
#endif
#endif

namespace {
std::atomic<bool> g_armed{false};
std::atomic<long> g_allocations{0};
std::atomic<unsigned long long> g_bytes{0};
std::atomic<long> g_locks{0};
}  // namespace

namespace evlife::test {

#ifdef EVLIFE_PROBE_DISABLED
bool allocation_probe_available() noexcept { return false; }
#else
bool allocation_probe_available() noexcept { return true; }
#endif

AllocationProbe::AllocationProbe() noexcept {
  g_allocations = 0;
  g_bytes = 0;
  g_locks = 0;
  g_armed = true;
}
void AllocationProbe::disarm() noexcept { g_armed = false; }
long AllocationProbe::allocations() const noexcept { return g_allocations.load(); }
unsigned long long AllocationProbe::bytes() const noexcept { return g_bytes.load(); }
long AllocationProbe::locks() const noexcept { return g_locks.load(); }

}  // namespace evlife::test

#ifndef EVLIFE_PROBE_DISABLED
#include <dlfcn.h>
#include <pthread.h>

#include <cerrno>
#include <cstdlib>
#include <new>

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
}

namespace {
void note_allocation(std::size_t bytes) noexcept {
  if (!g_armed.load(std::memory_order_relaxed)) return;
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  g_bytes.fetch_add(bytes, std::memory_order_relaxed);
}
}  // namespace

// Defined in the executable, these take precedence over libc's for every
// caller in the process (the library object is pulled in by AllocationProbe).
extern "C" {
void* malloc(std::size_t n) {
  note_allocation(n);
  return __libc_malloc(n);
}
void* calloc(std::size_t a, std::size_t b) {
  note_allocation(a * b);
  return __libc_calloc(a, b);
}
void* realloc(void* p, std::size_t n) {
  note_allocation(n);
  return __libc_realloc(p, n);
}
int posix_memalign(void** out, std::size_t align, std::size_t n) {
  note_allocation(n);
  *out = __libc_memalign(align, n);
  return *out != nullptr ? 0 : ENOMEM;
}
void* aligned_alloc(std::size_t align, std::size_t n) {
  note_allocation(n);
  return __libc_memalign(align, n);
}
int pthread_mutex_lock(pthread_mutex_t* m) {
  if (g_armed.load(std::memory_order_relaxed)) g_locks.fetch_add(1, std::memory_order_relaxed);
  using Fn = int (*)(pthread_mutex_t*);
  static const Fn real = reinterpret_cast<Fn>(dlsym(RTLD_NEXT, "pthread_mutex_lock"));
  return real(m);
}
}  // extern "C"

void* operator new(std::size_t n) {
  note_allocation(n);
  if (void* p = __libc_malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
#endif
