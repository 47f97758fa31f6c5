#include "plane_draws.h"

#include <algorithm>
#include <cmath>

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && defined(__linux__)
#define EVLIFE_DRAWS_AVX2 1
#include <immintrin.h>
#endif

namespace evlife::detail {
namespace {

// One draw after the other (the definition of best_of_draws()).
__attribute__((always_inline)) inline PlaneCandidate draw_planes(const WindowSamples& w, EventRng& rng, int iterations,
                                                                 const int* budget, float tol_floor2,
                                                                 float tol_fraction2, PlaneCandidate best) noexcept {
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
    const PlaneCandidate c = plane_candidate(w, gx, gy, tol_floor2, tol_fraction2);
    if (c.support > best.support) {
      best = c;
      iterations = std::min(iterations, budget[c.support - 1]);
    }
  }
  return best;
}

#if defined(EVLIFE_DRAWS_AVX2)
__attribute__((target("default")))
#endif
PlaneCandidate draws(const WindowSamples& w, EventRng& rng, int iterations, const int* budget, float tol_floor2,
                     float tol_fraction2, PlaneCandidate best) noexcept {
  return draw_planes(w, rng, iterations, budget, tol_floor2, tol_fraction2, best);
}

#if defined(EVLIFE_DRAWS_AVX2)
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
__attribute__((target("avx2"))) PlaneCandidate draws(const WindowSamples& w, EventRng& rng, int iterations,
                                                     const int* budget, float tol_floor2, float tol_fraction2,
                                                     PlaneCandidate best) noexcept {
  const int count = w.count;
  if (count > 16) {
    return draw_planes(w, rng, iterations, budget, tol_floor2, tol_fraction2, best);
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

PlaneCandidate best_of_draws(const WindowSamples& w, EventRng& rng, int iterations, const int* budget,
                             float tol_floor2, float tol_fraction2, PlaneCandidate best) noexcept {
  return draws(w, rng, iterations, budget, tol_floor2, tol_fraction2, best);
}

}  // namespace evlife::detail
