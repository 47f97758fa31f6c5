#include "evlife/render/completeness.h"

#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "evlife/render/sharpness.h"

namespace evlife::render {

Completeness measure_completeness(const cv::Mat& reference_mask, const cv::Mat& drawn_mask) {
  if (reference_mask.type() != CV_8UC1 || drawn_mask.type() != CV_8UC1 || reference_mask.size() != drawn_mask.size())
    throw std::invalid_argument("completeness: masks must be CV_8UC1 of one size");
  const cv::Mat edges = edge_mask(reference_mask);
  cv::Mat near_drawn;
  cv::dilate(drawn_mask, near_drawn, cv::Mat::ones(3, 3, CV_8UC1));
  cv::Mat covered;
  cv::bitwise_and(edges, near_drawn, covered);
  Completeness c;
  c.reference_edge_pixels = static_cast<std::size_t>(cv::countNonZero(edges));
  c.covered_pixels = static_cast<std::size_t>(cv::countNonZero(covered));
  return c;
}

}  // namespace evlife::render
