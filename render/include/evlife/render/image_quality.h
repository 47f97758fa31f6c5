// Complete *and* sharp: the quality of event images of one instant, compared
// the same way for every method (fixed windows of several lengths, lifetimes).
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include <opencv2/core.hpp>

#include "evlife/render/completeness.h"
#include "evlife/render/sharpness.h"

namespace evlife::render {

struct ImageQuality {
  Sharpness sharpness;
  Completeness completeness;  ///< against the instant's best fixed window

  /// completeness x thin-edge share, 0..1: high only when complete and sharp
  /// (NaN where no reference edge says what complete is).
  double score() const noexcept { return completeness.share() * sharpness.thin_edge_share(); }
  ImageQuality& operator+=(const ImageQuality& o) noexcept {
    sharpness += o.sharpness;
    completeness += o.completeness;
    return *this;
  }
};

/// `masks`: images of one instant (CV_8UC1, one size), the first
/// `fixed_windows` of them fixed-window images. The reference for
/// completeness is the fixed window with the most thin-edge pixels (the best
/// a fixed window does at this instant, known only in hindsight).
std::vector<ImageQuality> compare_images(std::span<const cv::Mat> masks, std::size_t fixed_windows);

}  // namespace evlife::render
