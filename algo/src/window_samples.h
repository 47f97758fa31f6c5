// The past events of one N x N window, relative to the new event, stored as
// structure-of-arrays so that RANSAC's support count vectorizes.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace evlife::detail {

constexpr int kMaxWindowSide = 15;
constexpr int kMaxNeighbours = kMaxWindowSide * kMaxWindowSide - 1;  // 224, a multiple of 8

struct WindowSamples {
  float dx[kMaxNeighbours];     // px
  float dy[kMaxNeighbours];     // px
  float dt_us[kMaxNeighbours];  // <= 0: past events only
  int count = 0;

  void add(float x, float y, float t) noexcept {
    dx[count] = x;
    dy[count] = y;
    dt_us[count] = t;
    ++count;
  }

  /// Keeps the `keep` most recent samples (paper Fig. 6: the newer half),
  /// preserving gather order among them so results do not depend on the
  /// selection algorithm.
  void keep_newest(int keep) noexcept {
    if (count <= keep) return;
    float sorted[kMaxNeighbours];
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
    float n[kLanes] = {};
    const int end = padded_count();
    for (int k = 0; k < end; k += kLanes) {
      for (int l = 0; l < kLanes; ++l) {
        const float r = dt_us[k + l] - gx * dx[k + l] - gy * dy[k + l];
        n[l] += std::fabs(r) <= tol_us ? 1.0f : 0.0f;
      }
    }
    float total = 0.0f;
    for (int l = 0; l < kLanes; ++l) total += n[l];
    return static_cast<int>(total);
  }

  static constexpr int kLanes = 8;
};

}  // namespace evlife::detail
