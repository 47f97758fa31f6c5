#include "window_samples.h"

namespace evlife::detail {

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && defined(__linux__)
#define EVLIFE_RANK_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define EVLIFE_RANK_CLONES
#endif

EVLIFE_RANK_CLONES void WindowSamples::keep_newest_by_rank(int keep) noexcept {
  // Eight samples' ranks at once (one AVX register, two SSE/NEON ones).
  using Lanes8f = float __attribute__((vector_size(32)));
  using Lanes8i = std::int32_t __attribute__((vector_size(32)));
  constexpr int kRankLanes = 8;
  static_assert(kSampleCapacity >= (kMaxNeighbours + kRankLanes - 1) / kRankLanes * kRankLanes);
  const int end = (count + kRankLanes - 1) / kRankLanes * kRankLanes;
  for (int k = count; k < end; ++k) dt_us[k] = -std::numeric_limits<float>::infinity();
  // Lanes k..k+7 against every sample j: samples before them count when as
  // new or newer, after them when newer, and among the eight themselves by
  // index (ties: gather order).
  for (int k = 0; k < count; k += kRankLanes) {
    Lanes8f t;
    __builtin_memcpy(&t, dt_us + k, sizeof t);
    Lanes8i rank = {};
    for (int j = 0; j < k; ++j) rank -= (dt_us[j] >= t);
    const Lanes8i index = Lanes8i{0, 1, 2, 3, 4, 5, 6, 7} + k;
    for (int j = k; j < k + kRankLanes; ++j) rank -= (dt_us[j] > t) | ((dt_us[j] == t) & (j < index));
    for (int j = k + kRankLanes; j < end; ++j) rank -= (dt_us[j] > t);
    __builtin_memcpy(rank_ + k, &rank, sizeof rank);
  }
  // Compaction without a branch to mispredict: every sample is copied
  // (out <= k, so nothing unread is overwritten), the kept ones advance.
  int out = 0;
  for (int k = 0; k < count; ++k) {
    dx[out] = dx[k];
    dy[out] = dy[k];
    dt_us[out] = dt_us[k];
    out += static_cast<int>(rank_[k] < keep);
  }
  count = out;
}

}  // namespace evlife::detail
