#include "window_samples.h"

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && defined(__linux__)
#define EVLIFE_RANK_AVX2 1
#include <immintrin.h>

#include <array>
#include <cstring>
#endif

namespace evlife::detail {
namespace {

constexpr int kRankLanes = 8;
using Lanes8f = float __attribute__((vector_size(32)));
using Lanes8i = std::int32_t __attribute__((vector_size(32)));

// rank_[k] = the number of samples newer than sample k, ties counted for the
// earlier-gathered one (integers: the same whichever instruction set runs).
// Inlined into each version of keep_newest_by_rank(), compiled for its target.
__attribute__((always_inline)) inline void rank_samples(float* dt_us, int* rank_out, int count) noexcept {
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
    __builtin_memcpy(rank_out + k, &rank, sizeof rank);
  }
}

#if defined(EVLIFE_RANK_AVX2)
// For each 8-bit mask of kept lanes: the kept lanes' indices in order, one
// byte each (the rest 0), for a left-packing permutation.
constexpr std::array<std::uint64_t, 256> make_pack_table() {
  std::array<std::uint64_t, 256> table{};
  for (unsigned m = 0; m < 256; ++m) {
    std::uint64_t packed = 0;
    int out = 0;
    for (unsigned lane = 0; lane < 8; ++lane) {
      if ((m >> lane) & 1U) packed |= std::uint64_t{lane} << (8 * out++);
    }
    table[m] = packed;
  }
  return table;
}
constexpr std::array<std::uint64_t, 256> kPackTable = make_pack_table();
#endif

#if defined(EVLIFE_RANK_AVX2)
// Two versions chosen at load time (GCC function multi-versioning): the AVX2
// one packs the kept samples eight at a time with a lane permutation; both
// move the same values to the same places.
__attribute__((target("default")))
#endif
void select_newest(WindowSamples& w, int keep) noexcept {
  float* dx = w.dx;
  float* dy = w.dy;
  float* dt_us = w.dt_us;
  const int count = w.count;
  rank_samples(dt_us, w.rank_, count);
  const int* rank_ = w.rank_;
  // Compaction without a branch to mispredict: every sample is copied
  // (out <= k, so nothing unread is overwritten), the kept ones advance.
  int out = 0;
  for (int k = 0; k < count; ++k) {
    dx[out] = dx[k];
    dy[out] = dy[k];
    dt_us[out] = dt_us[k];
    out += static_cast<int>(rank_[k] < keep);
  }
  w.count = out;
}

#if defined(EVLIFE_RANK_AVX2)
__attribute__((target("avx2"))) void select_newest(WindowSamples& w, int keep) noexcept {
  float* dx = w.dx;
  float* dy = w.dy;
  float* dt_us = w.dt_us;
  const int count = w.count;
  rank_samples(dt_us, w.rank_, count);
  const int* rank_ = w.rank_;
  // Eight samples at a time: the kept ones packed to the front of the lanes,
  // stored at `out`. The stores reach at most k + 8 (out <= k): lanes already
  // read. Lanes past count are never kept.
  const __m256i keep_v = _mm256_set1_epi32(keep);
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i count_v = _mm256_set1_epi32(count);
  int out = 0;
  for (int k = 0; k < count; k += kRankLanes) {
    const __m256i rank = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(rank_ + k));
    const __m256i index = _mm256_add_epi32(lane, _mm256_set1_epi32(k));
    const __m256i take = _mm256_and_si256(_mm256_cmpgt_epi32(keep_v, rank), _mm256_cmpgt_epi32(count_v, index));
    const auto mask = static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(take)));
    const __m256i perm = _mm256_cvtepu8_epi32(_mm_cvtsi64_si128(static_cast<long long>(kPackTable[mask])));
    const __m256 vx = _mm256_permutevar8x32_ps(_mm256_loadu_ps(dx + k), perm);
    const __m256 vy = _mm256_permutevar8x32_ps(_mm256_loadu_ps(dy + k), perm);
    const __m256 vt = _mm256_permutevar8x32_ps(_mm256_loadu_ps(dt_us + k), perm);
    _mm256_storeu_ps(dx + out, vx);
    _mm256_storeu_ps(dy + out, vy);
    _mm256_storeu_ps(dt_us + out, vt);
    out += __builtin_popcount(mask);
  }
  w.count = out;
}
#endif

}  // namespace

void WindowSamples::keep_newest_by_rank(int keep) noexcept { select_newest(*this, keep); }

}  // namespace evlife::detail
