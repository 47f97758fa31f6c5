// Counts heap allocations and mutex locks made while a probe is armed, by
// interposing malloc & co., operator new and pthread_mutex_lock in the test
// executable that links this library. Proves "no allocation, no lock" for
// per-event code paths. Unavailable under sanitizers (they own the allocator).
#pragma once

namespace evlife::test {

/// False when built with a sanitizer: tests should GTEST_SKIP().
bool allocation_probe_available() noexcept;

/// Counts allocations and locks between construction and disarm()/destruction.
class AllocationProbe {
 public:
  AllocationProbe() noexcept;
  ~AllocationProbe() { disarm(); }
  AllocationProbe(const AllocationProbe&) = delete;
  AllocationProbe& operator=(const AllocationProbe&) = delete;

  void disarm() noexcept;
  long allocations() const noexcept;
  unsigned long long bytes() const noexcept;  ///< requested by those allocations
  long locks() const noexcept;
};

}  // namespace evlife::test
