#include "censored_refit.h"

namespace evlife::detail {

// Out of line: inlined into LifetimeEstimator::process() its sums spilled to
// the stack (refit 47 -> 150 ns/event on garfield.mat).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && defined(__linux__)
__attribute__((target_clones("avx2", "default")))
#endif
CensoredRefit refit_without_censored(const WindowSamples& nb, float gx, float gy, float tol2_us2, double ux, double uy,
                                     double lifetime_us, double censor_us, double lambda, double prior_lifetime_us,
                                     double max_share) noexcept {
  // Less than this sum of squares, px^2, along the motion: the samples left
  // do not determine the slope (one row across the motion, or none).
  constexpr double kMinSpreadPx2 = 1.0;
  using L4f = WindowSamples::Lanes4f;
  using L4i = WindowSamples::Lanes4i;
  using L4d = double __attribute__((vector_size(32)));
  // Four samples at a time, taken by selection, not a branch (whether a
  // sample is censored is as unpredictable as the jitter), in float lanes
  // (SSE2 has no 64-bit integer to double conversion for a double mask); the
  // sums in double. The new event is s = 0, dt = 0.
  L4d n{1.0, 0.0, 0.0, 0.0}, ss{}, st{}, sss{}, sst{}, stt{};
  const auto fux = static_cast<float>(ux), fuy = static_cast<float>(uy);
  const auto tau = static_cast<float>(lifetime_us), limit = static_cast<float>(-censor_us);
  const L4f zero = {}, one = {1.0f, 1.0f, 1.0f, 1.0f};
  for (int k = 0; k < nb.padded_count(); k += WindowSamples::kLanes) {
    L4f vx, vy, vt;
    __builtin_memcpy(&vx, nb.dx + k, sizeof vx);
    __builtin_memcpy(&vy, nb.dy + k, sizeof vy);
    __builtin_memcpy(&vt, nb.dt_us + k, sizeof vt);
    const L4f r = vt - gx * vx - gy * vy;  // the test of WindowSamples::support()
    const L4f s_all = fux * vx + fuy * vy;
    const L4i take = (r * r <= tol2_us2) & (s_all * tau <= limit) & (L4i{0, 1, 2, 3} + k < nb.count);
    // Selected: the padding's dt is +inf, and 0 * inf is no zero.
    const L4d s = __builtin_convertvector(take ? s_all : zero, L4d);
    const L4d t = __builtin_convertvector(take ? vt : zero, L4d);
    n += __builtin_convertvector(take ? one : zero, L4d);
    ss += s;
    st += t;
    sss += s * s;
    sst += s * t;
    stt += t * t;
  }
  const auto sum = [](const L4d& v) { return (v[0] + v[1]) + (v[2] + v[3]); };
  return finish_censored_refit(sum(n), sum(ss), sum(st), sum(sss), sum(sst), sum(stt), lambda, prior_lifetime_us,
                               kMinSpreadPx2, max_share);
}

}  // namespace evlife::detail
