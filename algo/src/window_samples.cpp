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

// The lanes of samples k..k+7 set in `mask` packed to the front and stored
// at `out` (the stores reach at most out + 8 <= k + 8: lanes already read);
// returns the new out.
__attribute__((target("avx2"), always_inline)) inline int pack_samples(WindowSamples& w, int k, unsigned mask,
                                                                      int out) noexcept {
  const __m256i perm = _mm256_cvtepu8_epi32(_mm_cvtsi64_si128(static_cast<long long>(kPackTable[mask])));
  const __m256 vx = _mm256_permutevar8x32_ps(_mm256_loadu_ps(w.dx + k), perm);
  const __m256 vy = _mm256_permutevar8x32_ps(_mm256_loadu_ps(w.dy + k), perm);
  const __m256 vt = _mm256_permutevar8x32_ps(_mm256_loadu_ps(w.dt_us + k), perm);
  _mm256_storeu_ps(w.dx + out, vx);
  _mm256_storeu_ps(w.dy + out, vy);
  _mm256_storeu_ps(w.dt_us + out, vt);
  return out + __builtin_popcount(mask);
}
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
// Up to 32 samples (G groups of eight, padded with -inf): bit k set when
// fewer than `keep` samples are newer than sample k (ties not counted). Every
// sample is compared with every other: one broadcast, then G compares.
template <int G>
__attribute__((target("avx2"), always_inline)) inline unsigned fewer_newer_than(const float* dt_us, int keep) noexcept {
  __m256 t[G];
  __m256i newer[G];
  for (int i = 0; i < G; ++i) {
    t[i] = _mm256_loadu_ps(dt_us + 8 * i);
    newer[i] = _mm256_setzero_si256();
  }
  for (int j = 0; j < 8 * G; ++j) {
    const __m256 v = _mm256_broadcast_ss(dt_us + j);
    for (int i = 0; i < G; ++i) {
      newer[i] = _mm256_sub_epi32(newer[i], _mm256_castps_si256(_mm256_cmp_ps(v, t[i], _CMP_GT_OQ)));
    }
  }
  const __m256i keep_v = _mm256_set1_epi32(keep);
  unsigned mask = 0;
  for (int i = 0; i < G; ++i) {
    mask |= static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpgt_epi32(keep_v, newer[i]))))
            << (8 * i);
  }
  return mask;
}

// The same samples as the rank counting of the default version: a sample
// with fewer than `keep` newer ones is kept, except where the samples as new
// as the oldest of those (a tie) straddle the limit: then only the first of
// them in gather order fill it. Above 32 samples, rank_samples().
__attribute__((target("avx2"))) void select_newest(WindowSamples& w, int keep) noexcept {
  float* dt_us = w.dt_us;
  const int count = w.count;
  int out = 0;
  if (count <= 32) {
    const int groups = (count + kRankLanes - 1) / kRankLanes;
    // -inf after the samples, to the end of the last group (one store, no
    // loop to mispredict; count <= 32 leaves room).
    _mm256_storeu_ps(dt_us + count, _mm256_set1_ps(-std::numeric_limits<float>::infinity()));
    unsigned take = 0;
    switch (groups) {
      case 1: take = fewer_newer_than<1>(dt_us, keep); break;
      case 2: take = fewer_newer_than<2>(dt_us, keep); break;
      case 3: take = fewer_newer_than<3>(dt_us, keep); break;
      default: take = fewer_newer_than<4>(dt_us, keep); break;
    }
    take &= count == 32 ? ~0U : (1U << count) - 1U;  // (the -inf padding is never kept anyway)
    if (int excess = __builtin_popcount(take) - keep; excess > 0) {
      // The oldest kept time (a minimum over the groups, the others +inf),
      // then the last `excess` samples of that time in gather order dropped.
      const __m256 none = _mm256_set1_ps(std::numeric_limits<float>::infinity());
      __m256 oldest = none;
      for (int i = 0; i < groups; ++i) {
        const __m256i bits = _mm256_and_si256(_mm256_set1_epi32(static_cast<int>(take >> (8 * i))),
                                              _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128));
        const __m256 kept = _mm256_castsi256_ps(_mm256_cmpeq_epi32(bits, _mm256_setzero_si256()));
        oldest = _mm256_min_ps(oldest, _mm256_blendv_ps(_mm256_loadu_ps(dt_us + 8 * i), none, kept));
      }
      oldest = _mm256_min_ps(oldest, _mm256_permute2f128_ps(oldest, oldest, 1));
      oldest = _mm256_min_ps(oldest, _mm256_shuffle_ps(oldest, oldest, _MM_SHUFFLE(1, 0, 3, 2)));
      oldest = _mm256_min_ps(oldest, _mm256_shuffle_ps(oldest, oldest, _MM_SHUFFLE(2, 3, 0, 1)));
      unsigned ties = 0;
      for (int i = 0; i < groups; ++i) {
        ties |= static_cast<unsigned>(_mm256_movemask_ps(_mm256_cmp_ps(_mm256_loadu_ps(dt_us + 8 * i), oldest, _CMP_EQ_OQ)))
                << (8 * i);
      }
      ties &= take;
      for (; excess > 0; --excess) {
        const unsigned last = 1U << (31 - __builtin_clz(ties));
        ties &= ~last;
        take &= ~last;
      }
    }
    // Eight samples at a time: the kept ones packed to the front.
    for (int k = 0; k < count; k += kRankLanes) out = pack_samples(w, k, (take >> k) & 0xffU, out);
    w.count = out;
    return;
  }
  rank_samples(dt_us, w.rank_, count);
  const int* rank_ = w.rank_;
  // As above, by rank. Lanes past count are never kept.
  const __m256i keep_v = _mm256_set1_epi32(keep);
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i count_v = _mm256_set1_epi32(count);
  for (int k = 0; k < count; k += kRankLanes) {
    const __m256i rank = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(rank_ + k));
    const __m256i index = _mm256_add_epi32(lane, _mm256_set1_epi32(k));
    const __m256i take = _mm256_and_si256(_mm256_cmpgt_epi32(keep_v, rank), _mm256_cmpgt_epi32(count_v, index));
    out = pack_samples(w, k, static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(take))), out);
  }
  w.count = out;
}
#endif

#if defined(EVLIFE_RANK_AVX2)
__attribute__((target("default")))
#endif
bool gather_window_rows(WindowSamples&, const void*, std::size_t, int, int, int, int, int, int, int, std::int32_t,
                        float&) noexcept {
  return false;
}

#if defined(EVLIFE_RANK_AVX2)
__attribute__((target("avx2"), always_inline)) inline __m256 median3_lanes(__m256 a, __m256 b, __m256 c) noexcept {
  return _mm256_max_ps(_mm256_min_ps(a, b), _mm256_min_ps(_mm256_max_ps(a, b), c));
}

// window_timing_noise() of the rows x cols pixels in the rows' lanes (0
// past cols): for sides 3 and 5 the column medians lane by lane with
// median3() / median5()'s network (exact selections: the same values), then
// the median of those lanes.
__attribute__((target("avx2"))) float window_timing_noise_rows(__m256* noise_rows, int rows, int cols,
                                                               int side) noexcept {
  alignas(32) float lanes[8];
  if (side == 5) {
    for (int r = rows; r < 5; ++r) noise_rows[r] = _mm256_setzero_ps();
    const __m256* v = noise_rows;
    const __m256 f = _mm256_max_ps(_mm256_min_ps(v[0], v[1]), _mm256_min_ps(v[2], v[3]));
    const __m256 g = _mm256_min_ps(_mm256_max_ps(v[0], v[1]), _mm256_max_ps(v[2], v[3]));
    _mm256_store_ps(lanes, median3_lanes(v[4], f, g));
    return median5(lanes[0], lanes[1], lanes[2], lanes[3], lanes[4]);
  }
  if (side == 3) {
    for (int r = rows; r < 3; ++r) noise_rows[r] = _mm256_setzero_ps();
    _mm256_store_ps(lanes, median3_lanes(noise_rows[0], noise_rows[1], noise_rows[2]));
    return median3(lanes[0], lanes[1], lanes[2]);
  }
  // A larger window clipped to at most 5 x 5 by the sensor's corner.
  float noise[WindowSamples::kRowLanes * WindowSamples::kRowLanes];
  for (int r = 0; r < rows; ++r) {
    _mm256_store_ps(lanes, noise_rows[r]);
    for (int c = 0; c < cols; ++c) noise[r * cols + c] = lanes[c];
  }
  return window_timing_noise<kMaxWindowSide>(noise, rows, cols, side);
}

// A window row of at most five 8-byte pixels (t_rel, timing_noise_us) in two
// loads: pixels 0-3 and pixel 4 (read past the row where it is shorter; the
// plane's kGatherOverreadPixels cover the last row), the times in lanes 0-4.
// The kept lanes are packed to the front as select_newest() packs them. The
// timing noise: window_timing_noise(), its medians lane by lane over the rows.
__attribute__((target("avx2"))) bool gather_window_rows(WindowSamples& w, const void* plane, std::size_t width, int x,
                                                         int y, int x0, int x1, int y0, int y1, int side,
                                                         std::int32_t now_rel, float& timing_noise_us) noexcept {
  const auto* base = static_cast<const unsigned char*>(plane);
  const int cols = x1 - x0 + 1;
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i in_row = _mm256_cmpgt_epi32(_mm256_set1_epi32(cols), lane);
  const __m256i own_lane = _mm256_cmpeq_epi32(lane, _mm256_set1_epi32(x - x0));
  const __m256i never = _mm256_set1_epi32(kNeverRel);
  const __m256i now = _mm256_set1_epi32(now_rel);
  const __m256d now_d = _mm256_set1_pd(static_cast<double>(now_rel));
  const __m256i t_of = _mm256_setr_epi32(0, 2, 4, 6, 0, 0, 0, 0);
  const __m256i noise_of = _mm256_setr_epi32(1, 3, 5, 7, 1, 1, 1, 1);
  const __m256 dx = _mm256_cvtepi32_ps(_mm256_add_epi32(lane, _mm256_set1_epi32(x0 - x)));
  __m256 noise_rows[WindowSamples::kRowLanes];  // lanes past cols: 0
  int out = 0;
  for (int yy = y0; yy <= y1; ++yy) {
    const unsigned char* row = base + (static_cast<std::size_t>(yy) * width + static_cast<std::size_t>(x0)) * 8;
    const __m256i four = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row));
    long long fifth_bits;
    std::memcpy(&fifth_bits, row + 32, sizeof fifth_bits);
    const __m256i fifth = _mm256_set1_epi64x(fifth_bits);  // (t4, noise4) in every pair of lanes
    const __m256i t = _mm256_blend_epi32(_mm256_permutevar8x32_epi32(four, t_of), fifth, 0x10);
    const __m256 noise = _mm256_castsi256_ps(
        _mm256_blend_epi32(_mm256_permutevar8x32_epi32(four, noise_of), _mm256_srli_epi64(fifth, 32), 0x10));
    noise_rows[yy - y0] = _mm256_and_ps(noise, _mm256_castsi256_ps(in_row));
    // A past event that has fired (t_rel != kNeverRel, t_rel <= now_rel), not the own pixel.
    __m256i take = _mm256_andnot_si256(_mm256_cmpgt_epi32(t, now), _mm256_and_si256(in_row, _mm256_cmpgt_epi32(t, never)));
    take = _mm256_andnot_si256(_mm256_and_si256(own_lane, _mm256_set1_epi32(-static_cast<int>(yy == y))), take);
    // dt = t_rel - now_rel rounded once to float, as gather()'s int64 -> float:
    // the difference is exact in double.
    const __m128 dt_lo = _mm256_cvtpd_ps(_mm256_sub_pd(_mm256_cvtepi32_pd(_mm256_castsi256_si128(t)), now_d));
    const __m128 dt_hi = _mm256_cvtpd_ps(_mm256_sub_pd(_mm256_cvtepi32_pd(_mm256_extracti128_si256(t, 1)), now_d));
    const __m256 dt = _mm256_set_m128(dt_hi, dt_lo);
    const auto mask = static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(take)));
    const __m256i perm = _mm256_cvtepu8_epi32(_mm_cvtsi64_si128(static_cast<long long>(kPackTable[mask])));
    _mm256_storeu_ps(w.dx + out, _mm256_permutevar8x32_ps(dx, perm));
    _mm256_storeu_ps(w.dy + out, _mm256_set1_ps(static_cast<float>(yy - y)));
    _mm256_storeu_ps(w.dt_us + out, _mm256_permutevar8x32_ps(dt, perm));
    out += __builtin_popcount(mask);
  }
  w.count = out;
  timing_noise_us = window_timing_noise_rows(noise_rows, y1 - y0 + 1, cols, side);
  return true;
}
#endif

}  // namespace

void WindowSamples::keep_newest_by_rank(int keep) noexcept { select_newest(*this, keep); }

bool WindowSamples::gather_rows(const void* plane, std::size_t width, int x, int y, int x0, int x1, int y0, int y1,
                                int side, std::int32_t now_rel, float& timing_noise_us) noexcept {
  static_assert(kRowLanes <= 5, "gather_window_rows() reads five pixels a row");
  return gather_window_rows(*this, plane, width, x, y, x0, x1, y0, y1, side, now_rel, timing_noise_us);
}

}  // namespace evlife::detail
