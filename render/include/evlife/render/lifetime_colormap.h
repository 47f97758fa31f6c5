// Colour of an event by its lifetime, as in the paper's figures: short
// lifetimes (fast edges) blue, long lifetimes (slow edges) red. Log scale,
// because lifetimes of one scene easily span two decades.
#pragma once

#include <array>
#include <string>

#include <opencv2/core.hpp>

namespace evlife::render {

class LifetimeColormap {
 public:
  /// Lifetimes at or below min_us get the first colour, at or above max_us
  /// the last. Throws std::invalid_argument unless 0 < min_us < max_us.
  explicit LifetimeColormap(double min_us = 300.0, double max_us = 30000.0);

  cv::Vec3b color(float lifetime_us) const noexcept {
    return lut_[static_cast<std::size_t>(bin(lifetime_us))];
  }
  /// 0..255 position of a lifetime on the scale.
  int bin(float lifetime_us) const noexcept;

  double min_us() const noexcept { return min_us_; }
  double max_us() const noexcept { return max_us_; }

  /// A vertical colour bar with tick labels in ms, `height` pixels tall,
  /// titled "lifetime": the legend drawn next to lifetime images.
  cv::Mat legend(int height) const;

 private:
  double min_us_;
  double max_us_;
  double log_min_;
  double inv_log_span_;
  std::array<cv::Vec3b, 256> lut_{};
};

}  // namespace evlife::render
