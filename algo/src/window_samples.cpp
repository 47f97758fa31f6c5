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

// best_of_draws() with `support(gx, gy, tol2)` counting the samples within
// tolerance: the candidates of best_plane(), in its order.
template <class Support>
__attribute__((always_inline)) inline PlaneCandidate draw_planes(const WindowSamples& w, EventRng& rng, int iterations,
                                                                 const int* budget, float tol_floor2,
                                                                 float tol_fraction2, PlaneCandidate best,
                                                                 Support support) noexcept {
  const int count = w.count;
  for (int it = 0; it < iterations; ++it) {
    const std::uint32_t i = rng.below(static_cast<std::uint32_t>(count));
    std::uint32_t j = rng.below(static_cast<std::uint32_t>(count - 1));
    if (j >= i) ++j;
    const float det = w.dx[i] * w.dy[j] - w.dx[j] * w.dy[i];
    if (std::fabs(det) < 0.5f) continue;  // collinear with the origin
    const float inv_det = 1.0f / det;
    const float gx = (w.dt_us[i] * w.dy[j] - w.dt_us[j] * w.dy[i]) * inv_det;
    const float gy = (w.dx[i] * w.dt_us[j] - w.dx[j] * w.dt_us[i]) * inv_det;
    const float tol2 = std::max(tol_floor2, tol_fraction2 * (gx * gx + gy * gy));
    const int s = 1 + support(gx, gy, tol2);  // + the origin
    if (s > best.support) {
      best = {s, gx, gy, tol2};
      iterations = std::min(iterations, budget[s - 1]);
    }
  }
  return best;
}

#if defined(EVLIFE_RANK_AVX2)
__attribute__((target("default")))
#endif
PlaneCandidate best_of_draws(const WindowSamples& w, EventRng& rng, int iterations, const int* budget,
                             float tol_floor2, float tol_fraction2, PlaneCandidate best) noexcept {
  return draw_planes(w, rng, iterations, budget, tol_floor2, tol_fraction2, best,
                     [&w](float gx, float gy, float tol2) { return w.support(gx, gy, tol2); });
}

#if defined(EVLIFE_RANK_AVX2)
// The LCG jumps of draws 2m + 1 (lane m's first sample) and 2m + 2 (its
// second) from the state before a group of eight lanes.
struct LaneJumps {
  std::uint64_t first_a[8], first_c[8], second_a[8], second_c[8];
};
constexpr LaneJumps make_lane_jumps() {
  LaneJumps t{};
  for (int m = 0; m < 8; ++m) {
    t.first_a[m] = EventRng::jump(2 * m + 1).multiplier;
    t.first_c[m] = EventRng::jump(2 * m + 1).increment;
    t.second_a[m] = EventRng::jump(2 * m + 2).multiplier;
    t.second_c[m] = EventRng::jump(2 * m + 2).increment;
  }
  return t;
}
constexpr LaneJumps kLaneJumps = make_lane_jumps();

// a * s + c mod 2^64 in four 64-bit lanes (AVX2 multiplies 32 x 32 bits).
__attribute__((target("avx2"), always_inline)) inline __m256i lcg_lanes(const std::uint64_t* a, const std::uint64_t* c,
                                                                        __m256i s) noexcept {
  const __m256i av = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(a));
  const __m256i cross = _mm256_add_epi64(_mm256_mul_epu32(_mm256_srli_epi64(av, 32), s),
                                         _mm256_mul_epu32(av, _mm256_srli_epi64(s, 32)));
  return _mm256_add_epi64(_mm256_add_epi64(_mm256_mul_epu32(av, s), _mm256_slli_epi64(cross, 32)),
                          _mm256_loadu_si256(reinterpret_cast<const __m256i*>(c)));
}

// EventRng::below(n) of the states in lanes lo (lanes 0-3) and hi (4-7),
// as eight 32-bit lanes.
__attribute__((target("avx2"), always_inline)) inline __m256i below_lanes(__m256i lo, __m256i hi, __m256i n) noexcept {
  const __m256i r_lo = _mm256_srli_epi64(_mm256_mul_epu32(_mm256_srli_epi64(lo, 32), n), 32);
  const __m256i r_hi = _mm256_srli_epi64(_mm256_mul_epu32(_mm256_srli_epi64(hi, 32), n), 32);
  return _mm256_permutevar8x32_epi32(_mm256_or_si256(r_lo, _mm256_slli_epi64(r_hi, 32)),
                                     _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7));
}

// Eight candidates of draw_planes(), one a lane, drawn from the generator
// state before them: their planes (the same float operations lane by lane),
// supports with the origin (0 for a collinear draw: never taken) and the
// state after each lane's two draws.
struct LaneCandidates {
  __m256i support;
  __m256 gx, gy, tol2;
  __m256i after_lo, after_hi;  // lanes 0-3, 4-7
};

// Up to 16 samples (x, y, t: samples 0-7 and 8-15 of dx, dy, dt_us).
struct SamplesInLanes {
  __m256 x0, x1, y0, y1, t0, t1;
  bool upper;  // count > 8: an index may reach samples 8..15
};

__attribute__((target("avx2"), always_inline)) inline __m256 pick(__m256 lo, __m256 hi, bool upper,
                                                                   __m256i index) noexcept {
  const __m256 a = _mm256_permutevar8x32_ps(lo, index);
  if (!upper) return a;
  return _mm256_blendv_ps(a, _mm256_permutevar8x32_ps(hi, index),
                          _mm256_castsi256_ps(_mm256_cmpgt_epi32(index, _mm256_set1_epi32(7))));
}

__attribute__((target("avx2"), always_inline)) inline LaneCandidates score_lanes(const WindowSamples& w,
                                                                                 const SamplesInLanes& v,
                                                                                 std::uint64_t state, float tol_floor2,
                                                                                 float tol_fraction2) noexcept {
  const int count = w.count;
  LaneCandidates c;
  // Lane m draws with states 2m + 1 and 2m + 2, jumped to from `state`.
  const __m256i s = _mm256_set1_epi64x(static_cast<long long>(state));
  c.after_lo = lcg_lanes(kLaneJumps.second_a, kLaneJumps.second_c, s);
  c.after_hi = lcg_lanes(kLaneJumps.second_a + 4, kLaneJumps.second_c + 4, s);
  const __m256i i_v = below_lanes(lcg_lanes(kLaneJumps.first_a, kLaneJumps.first_c, s),
                                  lcg_lanes(kLaneJumps.first_a + 4, kLaneJumps.first_c + 4, s),
                                  _mm256_set1_epi64x(count));
  const __m256i j_drawn = below_lanes(c.after_lo, c.after_hi, _mm256_set1_epi64x(count - 1));
  // j >= i: j + 1.
  const __m256i j_v = _mm256_add_epi32(_mm256_add_epi32(j_drawn, _mm256_set1_epi32(1)), _mm256_cmpgt_epi32(i_v, j_drawn));
  const __m256 xi = pick(v.x0, v.x1, v.upper, i_v), yi = pick(v.y0, v.y1, v.upper, i_v);
  const __m256 ti = pick(v.t0, v.t1, v.upper, i_v);
  const __m256 xj = pick(v.x0, v.x1, v.upper, j_v), yj = pick(v.y0, v.y1, v.upper, j_v);
  const __m256 tj = pick(v.t0, v.t1, v.upper, j_v);
  const __m256 det = _mm256_sub_ps(_mm256_mul_ps(xi, yj), _mm256_mul_ps(xj, yi));
  // Not collinear with the origin: !(|det| < 0.5).
  const __m256 drawn = _mm256_cmp_ps(_mm256_and_ps(det, _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff))),
                                     _mm256_set1_ps(0.5f), _CMP_NLT_UQ);
  const __m256 inv_det = _mm256_div_ps(_mm256_set1_ps(1.0f), det);
  c.gx = _mm256_mul_ps(_mm256_sub_ps(_mm256_mul_ps(ti, yj), _mm256_mul_ps(tj, yi)), inv_det);
  c.gy = _mm256_mul_ps(_mm256_sub_ps(_mm256_mul_ps(xi, tj), _mm256_mul_ps(xj, ti)), inv_det);
  // std::max(floor, v): v where v > floor, else floor (also where v is NaN).
  c.tol2 = _mm256_max_ps(_mm256_mul_ps(_mm256_set1_ps(tol_fraction2),
                                       _mm256_add_ps(_mm256_mul_ps(c.gx, c.gx), _mm256_mul_ps(c.gy, c.gy))),
                         _mm256_set1_ps(tol_floor2));
  __m256i n = _mm256_setzero_si256();
  for (int k = 0; k < count; ++k) {
    const __m256 r = _mm256_sub_ps(_mm256_sub_ps(_mm256_set1_ps(w.dt_us[k]), _mm256_mul_ps(c.gx, _mm256_set1_ps(w.dx[k]))),
                                   _mm256_mul_ps(c.gy, _mm256_set1_ps(w.dy[k])));
    n = _mm256_sub_epi32(n, _mm256_castps_si256(_mm256_cmp_ps(_mm256_mul_ps(r, r), c.tol2, _CMP_LE_OQ)));
  }
  c.support = _mm256_and_si256(_mm256_sub_epi32(n, _mm256_set1_epi32(-1)), _mm256_castps_si256(drawn));
  return c;
}

// Where draw_planes() stands: the best plane, the iterations allowed, the
// iterations run and the generator's state after them.
struct DrawState {
  PlaneCandidate best;
  int iterations, it;
  std::uint64_t state;
};

// draw_planes()'s choice over eight lanes run from d.it on, without a
// branch: lane m improves on the best of the lanes before it (and of
// d.best), each improvement cuts the iterations to its budget, and lane m
// runs while d.it + m < the iterations after lane m - 1 (the lanes that
// run: a prefix). budget_lo/hi/top: budget[0..7], [8..15], [16].
__attribute__((target("avx2"), always_inline)) inline void replay_lanes(const LaneCandidates& c, __m256i budget_lo,
                                                                       __m256i budget_hi, int budget_top,
                                                                       DrawState& d) noexcept {
  const __m256i from_previous = _mm256_setr_epi32(0, 0, 1, 2, 3, 4, 5, 6);  // lane m - 1
  const __m256i from_2_before = _mm256_setr_epi32(0, 0, 0, 1, 2, 3, 4, 5);
  const __m256i from_4_before = _mm256_setr_epi32(0, 0, 0, 0, 0, 1, 2, 3);
  const __m256i best0 = _mm256_set1_epi32(d.best.support), iter0 = _mm256_set1_epi32(d.iterations);
  __m256i most = _mm256_max_epi32(c.support, best0);  // the best support up to each lane
  most = _mm256_max_epi32(most, _mm256_permutevar8x32_epi32(most, from_previous));
  most = _mm256_max_epi32(most, _mm256_permutevar8x32_epi32(most, from_2_before));
  most = _mm256_max_epi32(most, _mm256_permutevar8x32_epi32(most, from_4_before));
  const __m256i most_before = _mm256_blend_epi32(_mm256_permutevar8x32_epi32(most, from_previous), best0, 0x01);
  const __m256i improves = _mm256_cmpgt_epi32(c.support, most_before);
  // budget[support - 1] (support >= 1 where it improves; <= count + 1 <= 17).
  const __m256i index = _mm256_sub_epi32(c.support, _mm256_set1_epi32(1));
  __m256i cut = _mm256_blendv_epi8(_mm256_permutevar8x32_epi32(budget_lo, index),
                                   _mm256_permutevar8x32_epi32(budget_hi, index),
                                   _mm256_cmpgt_epi32(index, _mm256_set1_epi32(7)));
  cut = _mm256_blendv_epi8(cut, _mm256_set1_epi32(budget_top), _mm256_cmpgt_epi32(index, _mm256_set1_epi32(15)));
  __m256i after = _mm256_blendv_epi8(iter0, _mm256_min_epi32(iter0, cut), improves);
  after = _mm256_min_epi32(after, _mm256_permutevar8x32_epi32(after, from_previous));
  after = _mm256_min_epi32(after, _mm256_permutevar8x32_epi32(after, from_2_before));
  after = _mm256_min_epi32(after, _mm256_permutevar8x32_epi32(after, from_4_before));
  const __m256i before = _mm256_blend_epi32(_mm256_permutevar8x32_epi32(after, from_previous), iter0, 0x01);
  const auto runs = static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(
      _mm256_cmpgt_epi32(before, _mm256_add_epi32(_mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7), _mm256_set1_epi32(d.it))))));
  const unsigned improved = static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(improves))) & runs;
  if (runs == 0) return;
  const int ran = __builtin_popcount(runs);
  alignas(32) int after_l[8];
  alignas(32) std::uint64_t state_l[8];
  _mm256_store_si256(reinterpret_cast<__m256i*>(after_l), after);
  _mm256_store_si256(reinterpret_cast<__m256i*>(state_l), c.after_lo);
  _mm256_store_si256(reinterpret_cast<__m256i*>(state_l + 4), c.after_hi);
  if (improved != 0) {
    const int m = 31 - __builtin_clz(improved);  // the last improvement
    alignas(32) int support_l[8];
    alignas(32) float gx_l[8], gy_l[8], tol2_l[8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(support_l), c.support);
    _mm256_store_ps(gx_l, c.gx);
    _mm256_store_ps(gy_l, c.gy);
    _mm256_store_ps(tol2_l, c.tol2);
    d.best = {support_l[m], gx_l[m], gy_l[m], tol2_l[m]};
  }
  d.iterations = after_l[ran - 1];
  d.state = state_l[ran - 1];
  d.it += ran;
}

// Up to 16 samples: the draws eight at a time, each candidate in a lane,
// then draw_planes()'s choice replayed over the lanes; the lanes past the
// budget are drawn and scored but never taken. Where more than eight
// iterations remain, two groups of lanes are scored before either is
// replayed (the second does not wait for the first's replay). rng ends
// where draw_planes() leaves it: two draws per iteration run.
__attribute__((target("avx2"))) PlaneCandidate best_of_draws(const WindowSamples& w, EventRng& rng, int iterations,
                                                             const int* budget, float tol_floor2, float tol_fraction2,
                                                             PlaneCandidate best) noexcept {
  const int count = w.count;
  if (count > 16) {
    return draw_planes(w, rng, iterations, budget, tol_floor2, tol_fraction2, best,
                       [&w](float gx, float gy, float tol2) { return w.support(gx, gy, tol2); });
  }
  const SamplesInLanes v{_mm256_loadu_ps(w.dx),    _mm256_loadu_ps(w.dx + 8),    _mm256_loadu_ps(w.dy),
                         _mm256_loadu_ps(w.dy + 8), _mm256_loadu_ps(w.dt_us), _mm256_loadu_ps(w.dt_us + 8),
                         count > 8};
  // budget[0..count] (count <= 16; the table's row is longer).
  const __m256i budget_lo = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(budget));
  const __m256i budget_hi = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(budget + 8));
  const int budget_top = budget[16];
  constexpr EventRng::Jump kGroup = EventRng::jump(16);  // the draws of eight lanes
  DrawState d{best, iterations, 0, rng.state()};
  std::uint64_t state = d.state;
  while (d.it < d.iterations) {
    const bool two = d.iterations - d.it > 8;
    const std::uint64_t state2 = kGroup.multiplier * state + kGroup.increment;
    const LaneCandidates first = score_lanes(w, v, state, tol_floor2, tol_fraction2);
    if (two) {
      const LaneCandidates second = score_lanes(w, v, state2, tol_floor2, tol_fraction2);
      replay_lanes(first, budget_lo, budget_hi, budget_top, d);
      replay_lanes(second, budget_lo, budget_hi, budget_top, d);
      state = kGroup.multiplier * state2 + kGroup.increment;
    } else {
      replay_lanes(first, budget_lo, budget_hi, budget_top, d);
      state = state2;
    }
  }
  rng.set_state(d.state);
  return d.best;
}
#endif

}  // namespace

PlaneCandidate WindowSamples::best_of_draws(EventRng& rng, int iterations, const int* budget, float tol_floor2,
                                            float tol_fraction2, PlaneCandidate best) const noexcept {
  return evlife::detail::best_of_draws(*this, rng, iterations, budget, tol_floor2, tol_fraction2, best);
}

void WindowSamples::keep_newest_by_rank(int keep) noexcept { select_newest(*this, keep); }

bool WindowSamples::gather_rows(const void* plane, std::size_t width, int x, int y, int x0, int x1, int y0, int y1,
                                int side, std::int32_t now_rel, float& timing_noise_us) noexcept {
  static_assert(kRowLanes <= 5, "gather_window_rows() reads five pixels a row");
  return gather_window_rows(*this, plane, width, x, y, x0, x1, y0, y1, side, now_rel, timing_noise_us);
}

}  // namespace evlife::detail
