// The timing noise a window has observed, from the residual RMS that its
// pixels' last accepted fits stored, summarised robustly: the median over the
// window's N columns of each column's median over its N rows, a pixel without
// a fit (or outside the sensor) counting as 0.
//
// Why not the mean of the pixels that have a fit (the rule before): one fit
// through background activity (a lifetime of hundreds of ms, a residual of
// tens of ms) set the tolerance floor of every window holding it; the wider
// floor passed more noise, whose fits stored larger residuals. The floor ran
// away: on a static scene with 1 Hz/px of background activity, 77 % of the
// noise passed in the 7th second (tests/test_long_recordings.cpp), and on a
// real 6.9 s DVS128 recording the floor grew to 215 ms (algo/README.md, *Long
// recordings*). A median moves only when most of the window's pixels have
// fits this wide: the edges' own fits, not a few passing noise events.
// Medians of columns, then of those: min/max networks on whole rows
// (window_samples.cpp), a robust median all the same.
#pragma once

#include <algorithm>

namespace evlife::detail {

inline float median3(float a, float b, float c) noexcept { return std::max(std::min(a, b), std::min(std::max(a, b), c)); }

/// Median of five: the middle two of a..d (their smallest and largest
/// dropped) and e, then the median of those three.
inline float median5(float a, float b, float c, float d, float e) noexcept {
  const float f = std::max(std::min(a, b), std::min(c, d));
  const float g = std::min(std::max(a, b), std::max(c, d));
  return median3(e, f, g);
}

/// The (k + 1)-th smallest of v[0..n), v reordered (insertion sort: n is at
/// most a window side).
inline float kth_smallest(float* v, int n, int k) noexcept {
  for (int i = 1; i < n; ++i) {
    const float x = v[i];
    int j = i;
    for (; j > 0 && v[j - 1] > x; --j) v[j] = v[j - 1];
    v[j] = x;
  }
  return v[k];
}

/// The statistic above for a window of side `side` (odd, <= kMaxSide) of
/// which rows x cols pixels lie inside the sensor: their timing noise in
/// `noise`, row-major (0 = no fit).
template <int kMaxSide>
float window_timing_noise(const float* noise, int rows, int cols, int side) noexcept {
  float column_medians[kMaxSide];
  for (int c = 0; c < side; ++c) {
    float column[kMaxSide];
    for (int r = 0; r < side; ++r) column[r] = (r < rows && c < cols) ? noise[r * cols + c] : 0.0f;
    column_medians[c] = kth_smallest(column, side, side / 2);
  }
  return kth_smallest(column_medians, side, side / 2);
}

}  // namespace evlife::detail
