// Allocator of the estimator's per-pixel planes: blocks of 2 MiB or more are
// aligned to 2 MiB and, on Linux, marked for transparent huge pages
// (madvise), so that a window gather on a large sensor (rows 10-40 KiB
// apart) does not miss the TLB on every row. Elsewhere, or where the kernel
// declines, plain pages: a hint only, results never depend on it.
#pragma once

#include <cstddef>
#include <new>

namespace evlife::detail {

/// What allocate_large(bytes) takes from the heap: whole 2 MiB pages from
/// 2 MiB on (resident only once touched, but all of it under mlockall).
std::size_t large_allocation_bytes(std::size_t bytes) noexcept;

void* allocate_large(std::size_t bytes, std::size_t alignment);
void deallocate_large(void* p, std::size_t bytes, std::size_t alignment) noexcept;

template <class T>
struct LargePageAllocator {
  using value_type = T;
  LargePageAllocator() noexcept = default;
  template <class U>
  LargePageAllocator(const LargePageAllocator<U>&) noexcept {}  // NOLINT(google-explicit-constructor)
  T* allocate(std::size_t n) { return static_cast<T*>(allocate_large(n * sizeof(T), alignof(T))); }
  void deallocate(T* p, std::size_t n) noexcept { deallocate_large(p, n * sizeof(T), alignof(T)); }
  template <class U>
  bool operator==(const LargePageAllocator<U>&) const noexcept { return true; }
};

}  // namespace evlife::detail
