#include "evlife/algo/detail/large_page_allocator.h"

#include <algorithm>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace evlife::detail {
namespace {
constexpr std::size_t kHugePage = std::size_t{2} << 20;
}

std::size_t large_allocation_bytes(std::size_t bytes) noexcept {
  return bytes < kHugePage ? bytes : (bytes + kHugePage - 1) / kHugePage * kHugePage;
}

void* allocate_large(std::size_t bytes, std::size_t alignment) {
  if (bytes < kHugePage) return ::operator new(bytes, std::align_val_t{alignment});
  const std::size_t rounded = large_allocation_bytes(bytes);
  void* p = ::operator new(rounded, std::align_val_t{std::max(alignment, kHugePage)});
#if defined(MADV_HUGEPAGE)
  madvise(p, rounded, MADV_HUGEPAGE);  // a hint: its failure changes nothing but speed
#endif
  return p;
}

void deallocate_large(void* p, std::size_t bytes, std::size_t alignment) noexcept {
  if (bytes < kHugePage) {
    ::operator delete(p, std::align_val_t{alignment});
  } else {
    ::operator delete(p, std::align_val_t{std::max(alignment, kHugePage)});
  }
}

}  // namespace evlife::detail
