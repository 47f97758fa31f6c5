// Completeness of an event image, next to its sharpness: how much of the
// edges that a reference image shows it draws too. A thin image that leaves
// out half of the scene's edges is not better than a blurred complete one;
// `evlife eval` scores each method by completeness x thin-edge share.
#pragma once

#include <cstddef>
#include <limits>

#include <opencv2/core.hpp>

namespace evlife::render {

struct Completeness {
  std::size_t reference_edge_pixels = 0;  ///< edge pixels (extent >= 3) of the reference image
  std::size_t covered_pixels = 0;         ///< of those, drawn within 1 px by the measured image

  /// covered / reference edge pixels, 0..1; NaN for a reference without
  /// edges (nothing to be complete against: it was 1, a perfect score).
  double share() const noexcept {
    return reference_edge_pixels == 0 ? std::numeric_limits<double>::quiet_NaN()
                                      : static_cast<double>(covered_pixels) / static_cast<double>(reference_edge_pixels);
  }
  Completeness& operator+=(const Completeness& o) noexcept {
    reference_edge_pixels += o.reference_edge_pixels;
    covered_pixels += o.covered_pixels;
    return *this;
  }
};

/// Share of the reference's edge pixels that `drawn` has an active pixel
/// within 1 px of (its 3 x 3 neighbourhood): 1 px of slack, because a thin
/// edge and a blurred one are not drawn on the same pixels. Both masks
/// CV_8UC1 of one size, non-zero = active; throws std::invalid_argument
/// otherwise.
Completeness measure_completeness(const cv::Mat& reference_mask, const cv::Mat& drawn_mask);

}  // namespace evlife::render
