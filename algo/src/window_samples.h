// The past events of one N x N window, relative to the new event, stored as
// structure-of-arrays so that RANSAC's support count vectorizes.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace evlife::detail {

constexpr int kMaxWindowSide = 15;
constexpr int kMaxNeighbours = kMaxWindowSide * kMaxWindowSide - 1;  // 224
// Room for every pixel of the largest window (the gather writes before it
// decides to keep), rounded up to whole SIMD lanes.
constexpr int kSampleCapacity = (kMaxWindowSide * kMaxWindowSide + 3) / 4 * 4;  // 228

struct WindowSamples {
  float dx[kSampleCapacity];     // px
  float dy[kSampleCapacity];     // px
  float dt_us[kSampleCapacity];  // <= 0: past events only
  int count = 0;

  /// Keeps the `keep` most recent samples (paper Fig. 6: the newer half),
  /// preserving gather order among them so results do not depend on the
  /// selection algorithm.
  void keep_newest(int keep) noexcept {
    if (count <= keep) return;
    float sorted[kSampleCapacity];
    std::copy(dt_us, dt_us + count, sorted);
    std::nth_element(sorted, sorted + (keep - 1), sorted + count, [](float a, float b) { return a > b; });
    const float threshold = sorted[keep - 1];
    int strictly_newer = 0;
    for (int k = 0; k < count; ++k) strictly_newer += dt_us[k] > threshold;
    int ties_allowed = keep - strictly_newer;
    int out = 0;
    for (int k = 0; k < count; ++k) {
      const bool take = dt_us[k] > threshold || (dt_us[k] == threshold && ties_allowed-- > 0);
      if (!take) continue;
      dx[out] = dx[k];
      dy[out] = dy[k];
      dt_us[out] = dt_us[k];
      ++out;
    }
    count = out;
  }

  /// Pads the arrays to a multiple of kLanes with samples that support no
  /// plane (dt = +inf), so support() runs whole vector lanes.
  void pad() noexcept {
    for (int k = count; k < padded_count(); ++k) {
      dx[k] = 0.0f;
      dy[k] = 0.0f;
      dt_us[k] = std::numeric_limits<float>::infinity();
    }
  }
  int padded_count() const noexcept { return (count + kLanes - 1) / kLanes * kLanes; }

  /// Number of samples within `tol_us` of the plane dt = gx*dx + gy*dy
  /// (call pad() first).
  int support(float gx, float gy, float tol_us) const noexcept {
    std::int32_t n[kLanes] = {};
    const int end = padded_count();
    for (int k = 0; k < end; k += kLanes) {
      for (int l = 0; l < kLanes; ++l) {
        const float r = dt_us[k + l] - gx * dx[k + l] - gy * dy[k + l];
        n[l] -= -static_cast<std::int32_t>(std::fabs(r) <= tol_us);
      }
    }
    return n[0] + n[1] + n[2] + n[3];
  }

  static constexpr int kLanes = 4;  // one SSE register of floats
};

}  // namespace evlife::detail
