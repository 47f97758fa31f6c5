// Constant-memory latency histogram: log-linear buckets (16 per power of two,
// so a percentile is exact to within 1/16 = 6 %), exact max. One writer at a
// time (the merge role's holder) records; any thread may read percentiles.
// Why not render::Histogram (the value histogram, linear or log bins, for
// reports: single-threaded, bins set at run time, allocated once): this one
// lives in the per-event path of a running engine, so it is atomic, integer
// nanoseconds, a fixed std::array with no constructor work, and read by
// another thread while it is written.
#pragma once

#include <array>
#include <atomic>
#include <bit>
#include <cstdint>

namespace evlife::engine {

class LatencyHistogram {
 public:
  static constexpr int kSubBits = 4;
  static constexpr int kSub = 1 << kSubBits;
  static constexpr int kBuckets = (64 - kSubBits + 1) * kSub;

  /// Records `count` samples of `ns` nanoseconds (negative clamps to 0).
  /// Single writer only; no allocation, no lock.
  void record(std::int64_t ns, std::uint64_t count = 1) noexcept {
    const std::uint64_t v = ns < 0 ? 0 : static_cast<std::uint64_t>(ns);
    auto& b = buckets_[static_cast<std::size_t>(bucket_of(v))];
    b.store(b.load(std::memory_order_relaxed) + count, std::memory_order_relaxed);
    total_.store(total_.load(std::memory_order_relaxed) + count, std::memory_order_relaxed);
    if (v > max_.load(std::memory_order_relaxed)) max_.store(v, std::memory_order_relaxed);
  }

  std::uint64_t count() const noexcept { return total_.load(std::memory_order_relaxed); }
  std::uint64_t max_ns() const noexcept { return max_.load(std::memory_order_relaxed); }

  /// Upper bound of the bucket holding quantile q in [0, 1] (0 when empty),
  /// never above the exact max.
  std::uint64_t percentile_ns(double q) const noexcept {
    const std::uint64_t n = count();
    if (n == 0) return 0;
    std::uint64_t rank = static_cast<std::uint64_t>(q * static_cast<double>(n));
    if (rank >= n) rank = n - 1;
    std::uint64_t seen = 0;
    for (int i = 0; i < kBuckets; ++i) {
      seen += buckets_[static_cast<std::size_t>(i)].load(std::memory_order_relaxed);
      if (seen > rank) {
        const std::uint64_t hi = bucket_upper(i);
        const std::uint64_t mx = max_ns();
        return hi < mx ? hi : mx;
      }
    }
    return max_ns();
  }

  /// Samples above `ns` (to within the bucket holding it: those of that
  /// bucket count as above).
  std::uint64_t count_above(std::uint64_t ns) const noexcept {
    std::uint64_t n = 0;
    for (int i = bucket_of(ns); i < kBuckets; ++i) {
      n += buckets_[static_cast<std::size_t>(i)].load(std::memory_order_relaxed);
    }
    return n;
  }
  void reset() noexcept {
    for (auto& b : buckets_) b.store(0, std::memory_order_relaxed);
    total_.store(0, std::memory_order_relaxed);
    max_.store(0, std::memory_order_relaxed);
  }

  static constexpr int bucket_of(std::uint64_t v) noexcept {
    if (v < kSub) return static_cast<int>(v);
    const int e = 63 - std::countl_zero(v);  // >= kSubBits
    const int sub = static_cast<int>((v >> (e - kSubBits)) & (kSub - 1));
    return (e - kSubBits + 1) * kSub + sub;
  }
  /// Largest value that falls in bucket i.
  static constexpr std::uint64_t bucket_upper(int i) noexcept {
    if (i < kSub) return static_cast<std::uint64_t>(i);
    const int e = i / kSub + kSubBits - 1;
    const std::uint64_t sub = static_cast<std::uint64_t>(i % kSub);
    const std::uint64_t lo = (std::uint64_t{1} << e) | (sub << (e - kSubBits));
    return lo + (std::uint64_t{1} << (e - kSubBits)) - 1;
  }

 private:
  std::array<std::atomic<std::uint64_t>, kBuckets> buckets_{};
  std::atomic<std::uint64_t> total_{0};
  std::atomic<std::uint64_t> max_{0};
};

}  // namespace evlife::engine
