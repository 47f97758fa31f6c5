// The past events of one N x N window, relative to the new event, stored as
// structure-of-arrays so that RANSAC's support count vectorizes.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "time_plane.h"
#include "window_noise.h"

namespace evlife::detail {

constexpr int kMaxWindowSide = 15;
constexpr int kMaxNeighbours = kMaxWindowSide * kMaxWindowSide - 1;  // 224
// Room for every pixel of the largest window (the gather writes before it
// decides to keep), rounded up to whole SIMD lanes.
constexpr int kSampleCapacity = (kMaxWindowSide * kMaxWindowSide + 3) / 4 * 4;  // 228
// Pixels past the last one of a time plane that WindowSamples::gather_rows()
// may read (and ignore): a row's 8-byte pixels are read four and one at a time.
constexpr int kGatherOverreadPixels = 8;

struct WindowSamples {
  float dx[kSampleCapacity];     // px
  float dy[kSampleCapacity];     // px
  float dt_us[kSampleCapacity];  // <= 0: past events only
  int rank_[kSampleCapacity];    // scratch of keep_newest()
  int count = 0;
  int fired = 0;  // gather_newest(): the window's pixels that have fired, before the newer half

  /// Reads the window [x0, x1] x [y0, y1] around (x, y) of a time plane
  /// (`rows` points at row 0; `width` pixels a row): the pixels that have
  /// fired at or before now_rel, except (x, y) itself, become the samples, in
  /// row-major order. Also returns the window's timing noise (window_noise.h)
  /// for a window of side `side`, of which [x0, x1] x [y0, y1] is inside the
  /// sensor.
  template <class Pixel>
  void gather(const Pixel* rows, std::size_t width, int x, int y, int x0, int x1, int y0, int y1, int side,
              std::int32_t now_rel, float& timing_noise_us) noexcept {
    float noise[kMaxWindowSide * kMaxWindowSide];
    int pixel = 0;
    int gathered = 0;
    for (int yy = y0; yy <= y1; ++yy) {
      const Pixel* row = rows + static_cast<std::size_t>(yy) * width;
      const auto ddy = static_cast<float>(yy - y);
      for (int xx = x0; xx <= x1; ++xx) {
        noise[pixel++] = row[xx].timing_noise_us;
        // Written unconditionally, kept by advancing the count (no branch to
        // mispredict): a past event that has fired.
        const std::int32_t t = row[xx].t_rel;
        dx[gathered] = static_cast<float>(xx - x);
        dy[gathered] = ddy;
        dt_us[gathered] = static_cast<float>(static_cast<std::int64_t>(t) - now_rel);
        gathered += static_cast<int>((t != kNeverRel) & (t <= now_rel) & ((xx != x) | (yy != y)));
      }
    }
    count = gathered;
    timing_noise_us = window_timing_noise<kMaxWindowSide>(noise, y1 - y0 + 1, x1 - x0 + 1, side);
  }

  /// gather() of every window pixel but (x, y) itself, then keep_newest(keep):
  /// the same samples in the same order. Pixel: 8 bytes, the int32 t_rel
  /// first, the float timing_noise_us second; the plane must hold
  /// kGatherOverreadPixels readable pixels after its last one. Windows of at
  /// most kRowLanes x kRowLanes pixels are read a row at a time with AVX2
  /// where the CPU has it (gather_rows(), window_samples.cpp).
  template <class Pixel>
  void gather_newest(const Pixel* rows, std::size_t width, int x, int y, int x0, int x1, int y0, int y1, int side,
                     std::int32_t now_rel, int keep, float& timing_noise_us) noexcept {
    static_assert(sizeof(Pixel) == 8 && offsetof(Pixel, t_rel) == 0 && offsetof(Pixel, timing_noise_us) == 4);
    if (x1 - x0 >= kRowLanes || y1 - y0 >= kRowLanes ||
        !gather_rows(rows, width, x, y, x0, x1, y0, y1, side, now_rel, timing_noise_us)) {
      gather(rows, width, x, y, x0, x1, y0, y1, side, now_rel, timing_noise_us);
    }
    fired = count;
    keep_newest(keep);
  }
  static constexpr int kRowLanes = 5;

  /// The rows of gather_newest() (pixels as gather_newest() describes, at
  /// `plane`), the own pixel left out; false when the CPU has no AVX2 (then
  /// nothing is written).
  bool gather_rows(const void* plane, std::size_t width, int x, int y, int x0, int x1, int y0, int y1, int side,
                   std::int32_t now_rel, float& timing_noise_us) noexcept;

  /// Keeps the `keep` most recent samples (paper Fig. 6: the newer half),
  /// in gather order; ties go to the earlier-gathered sample.
  void keep_newest(int keep) noexcept {
    if (count <= keep) return;
    if (count <= kRankCountingMax) {
      keep_newest_by_rank(keep);
    } else {
      keep_newest_by_selection(keep);
    }
  }

  /// Rank counting, O(count^2) but branch-free: faster than a selection
  /// algorithm for the windows of N <= 5. Defined in window_samples.cpp
  /// (on x86-64 also an AVX2 version, chosen at load time: the ranks are
  /// integers and the kept samples move unchanged, the same whichever runs).
  static constexpr int kRankCountingMax = 32;
  void keep_newest_by_rank(int keep) noexcept;

  /// The same selection in O(count) for large windows.
  void keep_newest_by_selection(int keep) noexcept {
    float sorted[kSampleCapacity];
    std::copy(dt_us, dt_us + count, sorted);
    std::nth_element(sorted, sorted + (keep - 1), sorted + count, [](float a, float b) { return a > b; });
    const float threshold = sorted[keep - 1];
    int ties_allowed = keep;
    for (int k = 0; k < count; ++k) ties_allowed -= dt_us[k] > threshold;
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

  /// Moves the time origin later by shift_us: the samples' times relative to
  /// an event shift_us earlier at the same pixel.
  void shift_times(float shift_us) noexcept {
    for (int k = 0; k < count; ++k) dt_us[k] += shift_us;
  }

  /// Pads the arrays to a multiple of kLanes with samples that support no
  /// plane (dt = +inf), so support() runs whole vector lanes.
  void pad() noexcept {
    // kLanes samples after the last, whatever count is: no loop to mispredict.
    static_assert(kSampleCapacity >= kMaxNeighbours + kLanes);
    for (int k = count; k < count + kLanes; ++k) {
      dx[k] = 0.0f;
      dy[k] = 0.0f;
      dt_us[k] = std::numeric_limits<float>::infinity();
    }
  }
  int padded_count() const noexcept { return (count + kLanes - 1) / kLanes * kLanes; }

  /// Number of samples within sqrt(tol2_us2) of the plane dt = gx*dx + gy*dy
  /// (call pad() first). GCC/Clang vector extensions: SSE on x86, NEON on ARM.
  int support(float gx, float gy, float tol2_us2) const noexcept {
    const int end = padded_count();
    Lanes4i n = {0, 0, 0, 0};
    for (int k = 0; k < end; k += kLanes) {
      Lanes4f vx, vy, vt;
      __builtin_memcpy(&vx, dx + k, sizeof vx);
      __builtin_memcpy(&vy, dy + k, sizeof vy);
      __builtin_memcpy(&vt, dt_us + k, sizeof vt);
      const Lanes4f r = vt - gx * vx - gy * vy;
      n -= (r * r <= tol2_us2);  // a true lane compares as -1
    }
    return n[0] + n[1] + n[2] + n[3];
  }

  static constexpr int kLanes = 4;  // one SSE / NEON register of floats
  using Lanes4f = float __attribute__((vector_size(16)));
  using Lanes4i = std::int32_t __attribute__((vector_size(16)));
};

}  // namespace evlife::detail
