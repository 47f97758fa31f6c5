#include "evlife/render/image_quality.h"

#include <stdexcept>

namespace evlife::render {

std::vector<ImageQuality> compare_images(std::span<const cv::Mat> masks, std::size_t fixed_windows) {
  if (fixed_windows == 0 || fixed_windows > masks.size())
    throw std::invalid_argument("compare_images: needs 1..masks.size() fixed-window images");
  std::vector<ImageQuality> q(masks.size());
  std::size_t best = 0;
  for (std::size_t m = 0; m < masks.size(); ++m) {
    q[m].sharpness = measure_sharpness(masks[m]);
    if (m < fixed_windows && q[m].sharpness.thin_edge_pixels > q[best].sharpness.thin_edge_pixels) best = m;
  }
  for (std::size_t m = 0; m < masks.size(); ++m) q[m].completeness = measure_completeness(masks[best], masks[m]);
  return q;
}

}  // namespace evlife::render
