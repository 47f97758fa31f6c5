#include "evlife/render/sharpness.h"

#include <algorithm>
#include <array>
#include <limits>
#include <stdexcept>

namespace evlife::render {

namespace {

// Writes into `runs` the length of the run of active pixels along (dx, dy)
// through every active pixel.
void run_lengths(const cv::Mat& mask, int dx, int dy, cv::Mat& runs) {
  runs.create(mask.size(), CV_32SC1);
  runs.setTo(0);
  const int w = mask.cols;
  const int h = mask.rows;
  auto walk = [&](int x, int y) {
    int start_x = x, start_y = y, len = 0;
    for (;; x += dx, y += dy) {
      const bool inside = x >= 0 && y >= 0 && x < w && y < h;
      const bool on = inside && mask.at<std::uint8_t>(y, x) != 0;
      if (on) {
        if (len == 0) {
          start_x = x;
          start_y = y;
        }
        ++len;
        continue;
      }
      for (int k = 0; k < len; ++k) runs.at<int>(start_y + k * dy, start_x + k * dx) = len;
      len = 0;
      if (!inside) return;
    }
  };
  // Start every line at a pixel whose predecessor lies outside the image.
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int px = x - dx, py = y - dy;
      if (px < 0 || py < 0 || px >= w || py >= h) walk(x, y);
    }
}

}  // namespace

Sharpness& Sharpness::operator+=(const Sharpness& o) noexcept {
  const auto sum = [](const Sharpness& s) {  // of the thicknesses (NaN mean: no edge pixel)
    return s.edge_pixels == 0 ? 0.0 : s.mean_edge_thickness_px * static_cast<double>(s.edge_pixels);
  };
  const double total = sum(*this) + sum(o);
  active_pixels += o.active_pixels;
  edge_pixels += o.edge_pixels;
  thin_edge_pixels += o.thin_edge_pixels;
  mean_edge_thickness_px = edge_pixels == 0 ? std::numeric_limits<double>::quiet_NaN() : total / static_cast<double>(edge_pixels);
  return *this;
}

cv::Mat edge_mask(const cv::Mat& mask) {
  if (mask.type() != CV_8UC1) throw std::invalid_argument("sharpness: mask must be CV_8UC1");
  static constexpr std::array<std::array<int, 2>, 4> kDirs{{{1, 0}, {0, 1}, {1, 1}, {1, -1}}};
  cv::Mat extent, runs;
  for (const auto& d : kDirs) {
    run_lengths(mask, d[0], d[1], runs);
    extent = extent.empty() ? runs.clone() : cv::max(extent, runs);
  }
  cv::Mat edges;
  cv::compare(extent, 3, edges, cv::CMP_GE);
  return edges;
}

cv::Mat thickness_map(const cv::Mat& mask) {
  if (mask.type() != CV_8UC1) throw std::invalid_argument("sharpness: mask must be CV_8UC1");
  cv::Mat horizontal, vertical;
  run_lengths(mask, 1, 0, horizontal);
  run_lengths(mask, 0, 1, vertical);
  return cv::min(horizontal, vertical);
}

Sharpness measure_sharpness(const cv::Mat& mask) {
  if (mask.type() != CV_8UC1) throw std::invalid_argument("sharpness: mask must be CV_8UC1");
  // Thickness across rows or columns (a blurred band is wide both ways at
  // its inside; diagonal runs would call its corners thin); extent along
  // any of the 4 directions (a diagonal line is an edge too).
  static constexpr std::array<std::array<int, 2>, 4> kDirs{{{1, 0}, {0, 1}, {1, 1}, {1, -1}}};
  cv::Mat thick, extent, runs;
  for (std::size_t k = 0; k < kDirs.size(); ++k) {
    run_lengths(mask, kDirs[k][0], kDirs[k][1], runs);
    if (k == 0) {
      thick = runs.clone();
      extent = runs.clone();
    } else {
      if (k == 1) thick = cv::min(thick, runs);
      extent = cv::max(extent, runs);
    }
  }
  Sharpness s;
  double thickness_sum = 0.0;
  for (int y = 0; y < mask.rows; ++y)
    for (int x = 0; x < mask.cols; ++x) {
      if (mask.at<std::uint8_t>(y, x) == 0) continue;
      ++s.active_pixels;
      if (extent.at<int>(y, x) < 3) continue;
      ++s.edge_pixels;
      const int t = thick.at<int>(y, x);
      thickness_sum += t;
      if (t <= 2) ++s.thin_edge_pixels;
    }
  if (s.edge_pixels > 0) s.mean_edge_thickness_px = thickness_sum / static_cast<double>(s.edge_pixels);
  return s;
}

}  // namespace evlife::render
