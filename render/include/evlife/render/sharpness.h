// A sharpness figure for event images, measured the same way for every
// method (lifetime or fixed window): how much of what is drawn lies on thin
// edges. Per active pixel, the run of active pixels through it is measured in
// 4 directions (horizontal, vertical, both diagonals): the longest run is its
// extent, the shorter of the horizontal and vertical runs its local thickness
// (diagonal runs would call a blurred band's corners thin). A pixel lies on an edge when
// its extent is >= 3 px (isolated dots are not edges), on a thin edge when in
// addition its thickness is <= 2 px (motion blur makes edges thick).
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>

#include <opencv2/core.hpp>

namespace evlife::render {

struct Sharpness {
  std::size_t active_pixels = 0;
  std::size_t edge_pixels = 0;       ///< extent >= 3
  std::size_t thin_edge_pixels = 0;  ///< extent >= 3 and thickness <= 2
  /// Mean thickness over edge pixels; NaN without one (0 read as perfectly sharp).
  double mean_edge_thickness_px = std::numeric_limits<double>::quiet_NaN();

  /// Share of active pixels on a thin edge, 0..1 (0 for an empty image).
  double thin_edge_share() const noexcept {
    return active_pixels == 0 ? 0.0 : static_cast<double>(thin_edge_pixels) / static_cast<double>(active_pixels);
  }
  Sharpness& operator+=(const Sharpness& o) noexcept;
};

/// `mask`: CV_8UC1, non-zero = active. Throws std::invalid_argument otherwise.
Sharpness measure_sharpness(const cv::Mat& mask);

/// The edge pixels of `mask` (extent >= 3): CV_8UC1, 255 on an edge, 0 elsewhere.
cv::Mat edge_mask(const cv::Mat& mask);

/// Thickness (shorter of the horizontal and vertical run) of each active pixel, 0 elsewhere (CV_32SC1).
cv::Mat thickness_map(const cv::Mat& mask);

}  // namespace evlife::render
