#include "inlier_sums.h"

namespace evlife::detail {
namespace {

using L4f = WindowSamples::Lanes4f;
using L4i = WindowSamples::Lanes4i;
using L4d = double __attribute__((vector_size(32)));

__attribute__((always_inline)) inline double hsum(const L4d& v) noexcept { return (v[0] + v[1]) + (v[2] + v[3]); }

// One body for every version (inlined into each, compiled for its target).
// A sample not taken adds +0 (its float lanes zeroed, then widened): the
// sums stay bit for bit as PlaneFit::add_if() leaves them.
__attribute__((always_inline)) inline bool sums_body(const WindowSamples& nb, float gx, float gy, float tol2_us2,
                                                     InlierSums& s) noexcept {
  constexpr float kExactDt = 2097152.0f;  // 2^21
  const int end = nb.padded_count();
  L4i small = {-1, -1, -1, -1};
  L4i n{};
  L4d sx{}, sy{}, st{}, sxx{}, sxy{}, syy{}, sxt{}, syt{}, stt{};
  for (int k = 0; k < end; k += WindowSamples::kLanes) {
    L4f vx, vy, vt;
    __builtin_memcpy(&vx, nb.dx + k, sizeof vx);
    __builtin_memcpy(&vy, nb.dy + k, sizeof vy);
    __builtin_memcpy(&vt, nb.dt_us + k, sizeof vt);
    const L4i in_window = L4i{0, 1, 2, 3} + k < nb.count;
    small &= (vt >= -kExactDt) | ~in_window;  // dt <= 0 always
    const L4f r = vt - gx * vx - gy * vy;
    const L4i take = (r * r <= tol2_us2) & in_window;
    n -= take;
    L4i bx, by, bt;
    __builtin_memcpy(&bx, &vx, sizeof bx);
    __builtin_memcpy(&by, &vy, sizeof by);
    __builtin_memcpy(&bt, &vt, sizeof bt);
    bx &= take;
    by &= take;
    bt &= take;
    __builtin_memcpy(&vx, &bx, sizeof vx);
    __builtin_memcpy(&vy, &by, sizeof vy);
    __builtin_memcpy(&vt, &bt, sizeof vt);
    const L4d x = __builtin_convertvector(vx, L4d);
    const L4d y = __builtin_convertvector(vy, L4d);
    const L4d t = __builtin_convertvector(vt, L4d);
    sx += x;
    sy += y;
    st += t;
    sxx += x * x;
    sxy += x * y;
    syy += y * y;
    sxt += x * t;
    syt += y * t;
    stt += t * t;
  }
  if ((small[0] & small[1] & small[2] & small[3]) == 0) return false;
  s.n = hsum(__builtin_convertvector(n, L4d));
  s.sx = hsum(sx);
  s.sy = hsum(sy);
  s.st = hsum(st);
  s.sxx = hsum(sxx);
  s.sxy = hsum(sxy);
  s.syy = hsum(syy);
  s.sxt = hsum(sxt);
  s.syt = hsum(syt);
  s.stt = hsum(stt);
  return true;
}

}  // namespace

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && defined(__linux__)
__attribute__((target_clones("avx2", "default")))
#endif
bool exact_inlier_sums(const WindowSamples& nb, float gx, float gy, float tol2_us2, InlierSums& sums) noexcept {
  return sums_body(nb, gx, gy, tol2_us2, sums);
}

}  // namespace evlife::detail
