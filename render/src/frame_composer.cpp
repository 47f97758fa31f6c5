#include "evlife/render/frame_composer.h"

#include "evlife/algo/parse_text.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace evlife::render {

namespace {
constexpr int kCaptionHeight = 24;
constexpr int kGap = 4;

std::string format_duration(std::int64_t us) {
  char buf[32];
  if (us % 1000 == 0)
    std::snprintf(buf, sizeof buf, "%lld ms", static_cast<long long>(us / 1000));
  else
    std::snprintf(buf, sizeof buf, "%.3g ms", static_cast<double>(us) / 1000.0);
  return buf;
}
}  // namespace

std::int64_t parse_duration_us(std::string_view text) {
  if (const auto us = parse_time_us(text)) return *us;  // the one time parser (algo/)
  throw std::invalid_argument("bad duration '" + std::string(text) + "' (" +
                              std::string(kTimeExamples) + ")");
}

std::vector<View> parse_view_mode(std::string_view mode) {
  if (mode == "lifetime") return {View{true, 0, "lifetime"}};
  if (mode == "compare") {
    return {View{false, 1000, "(a) fixed window 1 ms"}, View{false, 30000, "(b) fixed window 30 ms"},
            View{true, 0, "(c) lifetime (ours)"}};
  }
  if (mode.substr(0, 7) == "window:") {
    const std::int64_t w = parse_duration_us(mode.substr(7));
    if (w <= 0) throw std::invalid_argument("window must be longer than 0 in '" + std::string(mode) + "'");
    if (w > FixedWindowMap::kLongestWindowUs) {
      throw std::invalid_argument("window longer than the longest drawn exactly, " +
                                  std::to_string(FixedWindowMap::kLongestWindowUs / 1'000'000) + " s, in '" +
                                  std::string(mode) + "'");
    }
    return {View{false, w, "fixed window " + format_duration(w)}};
  }
  throw std::invalid_argument("unknown mode '" + std::string(mode) +
                              "' (use lifetime, window:<duration> e.g. window:30ms, or compare)");
}

ColorMode color_drawn(ColorMode asked, const std::vector<View>& views) noexcept {
  if (asked != ColorMode::lifetime) return asked;
  for (const auto& v : views)
    if (v.lifetime) return asked;
  return ColorMode::plain;
}

FrameComposer::FrameComposer(std::vector<View> views, FrameStyle style, std::string mode_name)
    : views_(std::move(views)), style_(style),
      colormap_(style.lifetime_min_us, style.lifetime_max_us), mode_name_(std::move(mode_name)) {
  if (views_.empty()) throw std::invalid_argument("FrameComposer: no view to draw");
  if (style_.scale < 1 || style_.scale > FrameStyle::kMaxScale)
    throw std::invalid_argument("scale must be 1.." + std::to_string(FrameStyle::kMaxScale) +
                                " (got " + std::to_string(style_.scale) + ")");
}

bool FrameComposer::has_legend() const noexcept {
  return style_.legend && color_drawn(style_.color, views_) == ColorMode::lifetime;
}

int FrameComposer::label_height() const noexcept {
  for (const auto& v : views_)
    if (!v.label.empty()) return 22;
  return 0;
}

cv::Size FrameComposer::frame_size(SensorSize sensor) const {
  const int n = static_cast<int>(views_.size());
  const int panel_w = sensor.width * style_.scale;
  const int panel_h = sensor.height * style_.scale;
  int w = n * panel_w + (n - 1) * kGap;
  int body_h = panel_h;
  if (has_legend()) {
    w += kGap + 96;
    body_h = std::max(panel_h, LifetimeColormap::kLegendMinHeight);  // a small sensor at scale 1
  }
  const int h = label_height() + body_h + (style_.caption ? kCaptionHeight : 0);
  return {w, h};
}

const cv::Mat& FrameComposer::compose(const ActiveEventMap& set, const FixedWindowMap& window,
                                      std::int64_t t_us, std::optional<std::int64_t> caption_t_us) {
  const SensorSize sensor = set.sensor();
  const cv::Size size = frame_size(sensor);
  frame_.create(size, CV_8UC3);
  frame_.setTo(cv::Scalar(40, 40, 40));  // grey gutters set the panels apart
  const int panel_w = sensor.width * style_.scale;
  const int panel_h = sensor.height * style_.scale;
  const int top = label_height();
  int x0 = 0;
  for (const auto& v : views_) {
    if (v.lifetime)
      paint_active(set, t_us, style_.color, colormap_, sensor_img_);
    else
      paint_window(window, t_us, v.window_us, style_.color, sensor_img_);
    cv::Mat dst = frame_(cv::Rect(x0, top, panel_w, panel_h));
    if (style_.scale == 1)
      sensor_img_.copyTo(dst);
    else
      cv::resize(sensor_img_, dst, dst.size(), 0, 0, cv::INTER_NEAREST);
    if (!v.label.empty()) {
      cv::putText(frame_, v.label, {x0 + 4, top - 6}, cv::FONT_HERSHEY_SIMPLEX, 0.5,
                  {255, 255, 255}, 1, cv::LINE_AA);
    }
    x0 += panel_w + kGap;
  }
  if (has_legend()) {
    if (legend_.rows != std::max(panel_h, LifetimeColormap::kLegendMinHeight)) legend_ = colormap_.legend(panel_h);
    legend_.copyTo(frame_(cv::Rect(x0, top, legend_.cols, legend_.rows)));
  }
  if (style_.caption) {
    char text[160];
    std::snprintf(text, sizeof text, "t = %.6f s   mode: %s   colour: %s",
                  static_cast<double>(caption_t_us.value_or(t_us)) * 1e-6, mode_name_.c_str(),
                  std::string(to_string(color_drawn(style_.color, views_))).c_str());
    cv::putText(frame_, text, {4, size.height - 7}, cv::FONT_HERSHEY_SIMPLEX, 0.45,
                {255, 255, 255}, 1, cv::LINE_AA);
  }
  return frame_;
}

}  // namespace evlife::render
