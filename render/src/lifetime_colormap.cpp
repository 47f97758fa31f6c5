#include "evlife/render/lifetime_colormap.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace evlife::render {

LifetimeColormap::LifetimeColormap(double min_us, double max_us) : min_us_(min_us), max_us_(max_us) {
  if (!(min_us > 0.0) || !(max_us > min_us)) {
    throw std::invalid_argument("lifetime colour range must satisfy 0 < min < max (got " +
                                std::to_string(min_us) + " us .. " + std::to_string(max_us) +
                                " us)");
  }
  log_min_ = std::log(min_us);
  inv_log_span_ = 1.0 / (std::log(max_us) - log_min_);
  // OpenCV's JET runs blue (0) -> red (255): exactly the paper's short -> long.
  cv::Mat ramp(1, 256, CV_8UC1);
  for (int i = 0; i < 256; ++i) ramp.at<std::uint8_t>(0, i) = static_cast<std::uint8_t>(i);
  cv::Mat colored;
  cv::applyColorMap(ramp, colored, cv::COLORMAP_JET);
  for (int i = 0; i < 256; ++i) lut_[static_cast<std::size_t>(i)] = colored.at<cv::Vec3b>(0, i);
  // Positive floats order like their bit patterns: key = exponent and top 8
  // mantissa bits; each key covers 1/256 of an octave.
  min_f_ = static_cast<float>(min_us);
  max_f_ = static_cast<float>(max_us);
  base_key_ = std::bit_cast<std::uint32_t>(min_f_) >> 15;
  const std::uint32_t top_key = std::bit_cast<std::uint32_t>(max_f_) >> 15;
  fast_table_.resize(top_key - base_key_ + 1);
  for (std::uint32_t key = base_key_; key <= top_key; ++key) {
    // Centre of the key's interval.
    const float lo = std::bit_cast<float>(key << 15);
    const float hi = std::bit_cast<float>((key + 1) << 15);
    const float mid = std::sqrt(lo * hi);
    fast_table_[key - base_key_] = static_cast<std::uint8_t>(bin(mid));
  }
}

int LifetimeColormap::bin(float lifetime_us) const noexcept {
  if (!(static_cast<double>(lifetime_us) > min_us_)) return 0;
  const double u = (std::log(static_cast<double>(lifetime_us)) - log_min_) * inv_log_span_;
  return static_cast<int>(std::lround(std::clamp(u, 0.0, 1.0) * 255.0));
}

cv::Mat LifetimeColormap::legend(int height) const {
  const int bar_w = 16;
  const int width = 96;
  const int top = 24;
  const int bottom = 10;
  height = std::max(height, kLegendMinHeight);
  cv::Mat img(height, width, CV_8UC3, cv::Scalar(0, 0, 0));
  cv::putText(img, "lifetime", {4, 15}, cv::FONT_HERSHEY_SIMPLEX, 0.45, {255, 255, 255}, 1,
              cv::LINE_AA);
  const int bar_h = height - top - bottom;
  // Long lifetimes on top (red), short at the bottom (blue).
  for (int r = 0; r < bar_h; ++r) {
    const int b = 255 - static_cast<int>(std::lround(255.0 * r / std::max(bar_h - 1, 1)));
    cv::line(img, {6, top + r}, {6 + bar_w, top + r}, cv::Scalar(lut_[static_cast<std::size_t>(b)]));
  }
  cv::rectangle(img, {6, top}, {6 + bar_w, top + bar_h - 1}, {200, 200, 200}, 1);
  // Ticks at 1-2-5 steps between min and max, labelled in ms (s from 1 s).
  std::vector<double> ticks;
  const int first_exp = static_cast<int>(std::floor(std::log10(min_us_)));
  const int last_exp = static_cast<int>(std::ceil(std::log10(max_us_)));
  for (int e = first_exp; e <= last_exp; ++e) {
    const double decade = std::pow(10.0, e);
    for (double m : {1.0, 2.0, 5.0}) {
      const double v = m * decade;
      if (v >= min_us_ * 0.999 && v <= max_us_ * 1.001) ticks.push_back(v);
    }
  }
  if (ticks.size() < 2) ticks = {min_us_, max_us_};  // a narrow range (6:9 ms) held none: label its ends
  if (ticks.size() > 7) {  // keep decades only when crowded
    std::vector<double> thinned;
    for (double v : ticks)
      if (std::fabs(std::log10(v) - std::round(std::log10(v))) < 1e-6) thinned.push_back(v);
    ticks = thinned;
  }
  if (ticks.size() > 7) {  // still crowded (a range of hundreds of decades overprinted): every k-th decade
    const std::size_t every = (ticks.size() + 6) / 7;
    std::vector<double> spaced;
    for (std::size_t i = 0; i < ticks.size(); i += every) spaced.push_back(ticks[i]);
    ticks = spaced;
  }
  for (double v : ticks) {
    const double u = (std::log(v) - log_min_) * inv_log_span_;
    const int y = top + static_cast<int>(std::lround((1.0 - u) * (bar_h - 1)));
    cv::line(img, {6 + bar_w, y}, {10 + bar_w, y}, {255, 255, 255}, 1);
    cv::putText(img, lifetime_tick_label(v), {13 + bar_w, y + 4}, cv::FONT_HERSHEY_SIMPLEX, 0.38, {255, 255, 255}, 1,
                cv::LINE_AA);
  }
  return img;
}

std::string lifetime_tick_label(double lifetime_us) {
  // %g: 0.05 ms (it was "%.1f": 0.0 ms for 10 and 20 µs); seconds from 1 s on, so that long ones fit the panel.
  char label[32];
  if (lifetime_us >= 1e6)
    std::snprintf(label, sizeof label, "%g s", lifetime_us / 1e6);
  else
    std::snprintf(label, sizeof label, "%g ms", lifetime_us / 1000.0);
  return label;
}

}  // namespace evlife::render
