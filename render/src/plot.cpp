#include "evlife/render/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace evlife::render {

namespace {

double nice_step(double span, int target_ticks) {
  const double raw = span / std::max(target_ticks, 1);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * mag >= raw) return m * mag;
  return 10.0 * mag;
}

std::string tick_label(double v, double step) {
  char buf[32];
  if (std::fabs(v) < step * 1e-6) v = 0.0;
  if (step >= 1.0 && std::fabs(v) < 1e7)
    std::snprintf(buf, sizeof buf, "%.0f", v);
  else if (step >= 0.1)
    std::snprintf(buf, sizeof buf, "%.1f", v);
  else if (step >= 0.01)
    std::snprintf(buf, sizeof buf, "%.2f", v);
  else
    std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

void dashed_line(cv::Mat& img, cv::Point a, cv::Point b, const cv::Scalar& c, int thickness) {
  const double len = std::hypot(b.x - a.x, b.y - a.y);
  const int n = std::max(1, static_cast<int>(len / 6.0));
  for (int i = 0; i < n; i += 2) {
    const double t0 = static_cast<double>(i) / n;
    const double t1 = std::min(1.0, static_cast<double>(i + 1) / n);
    cv::line(img, {a.x + static_cast<int>((b.x - a.x) * t0), a.y + static_cast<int>((b.y - a.y) * t0)},
             {a.x + static_cast<int>((b.x - a.x) * t1), a.y + static_cast<int>((b.y - a.y) * t1)}, c,
             thickness, cv::LINE_AA);
  }
}

}  // namespace

cv::Scalar series_color(int k) {
  static const cv::Scalar kColors[] = {{190, 110, 30}, {40, 40, 220},  {50, 160, 50},
                                       {160, 60, 160}, {20, 140, 230}, {140, 140, 20}};
  return kColors[static_cast<std::size_t>(k) % (sizeof kColors / sizeof kColors[0])];
}

cv::Mat draw_plot(const PlotOptions& o, const std::vector<PlotSeries>& series) {
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const auto& s : series) {
    if (s.x.size() != s.y.size()) throw std::invalid_argument("plot '" + o.title + "': series '" + s.label + "' has x and y of different sizes");
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      x0 = std::min(x0, s.x[i]);
      x1 = std::max(x1, s.x[i]);
      y0 = std::min(y0, s.y[i]);
      y1 = std::max(y1, s.y[i]);
    }
  }
  if (!std::isfinite(x0)) { x0 = 0; x1 = 1; y0 = 0; y1 = 1; }
  x0 = o.x_min.value_or(x0);
  x1 = o.x_max.value_or(x1);
  y0 = o.y_min.value_or(std::min(y0, 0.0));
  y1 = o.y_max.value_or(y1 * 1.05);
  if (!(x1 > x0)) x1 = x0 + 1.0;
  if (!(y1 > y0)) y1 = y0 + 1.0;

  cv::Mat img(o.height, o.width, CV_8UC3, cv::Scalar(255, 255, 255));
  const int left = 86, right = 20, top = 40, bottom = 56;
  const cv::Rect area(left, top, o.width - left - right, o.height - top - bottom);
  auto px = [&](double x) { return area.x + static_cast<int>(std::lround((x - x0) / (x1 - x0) * area.width)); };
  auto py = [&](double y) { return area.y + area.height - static_cast<int>(std::lround((y - y0) / (y1 - y0) * area.height)); };
  const cv::Scalar black(0, 0, 0), grid(225, 225, 225);
  const auto font = cv::FONT_HERSHEY_SIMPLEX;

  // Grid and ticks.
  const double xs = nice_step(x1 - x0, 8), ys = nice_step(y1 - y0, 6);
  const auto first_x = static_cast<long long>(std::ceil(x0 / xs));
  for (long long k = first_x; static_cast<double>(k) * xs <= x1 + xs * 1e-9; ++k) {
    const double v = static_cast<double>(k) * xs;
    const int x = px(v);
    cv::line(img, {x, area.y}, {x, area.y + area.height}, grid, 1);
    cv::line(img, {x, area.y + area.height}, {x, area.y + area.height + 5}, black, 1);
    const std::string t = tick_label(v, xs);
    int base = 0;
    const cv::Size sz = cv::getTextSize(t, font, 0.42, 1, &base);
    cv::putText(img, t, {x - sz.width / 2, area.y + area.height + 20}, font, 0.42, black, 1, cv::LINE_AA);
  }
  const auto first_y = static_cast<long long>(std::ceil(y0 / ys));
  for (long long k = first_y; static_cast<double>(k) * ys <= y1 + ys * 1e-9; ++k) {
    const double v = static_cast<double>(k) * ys;
    const int y = py(v);
    cv::line(img, {area.x, y}, {area.x + area.width, y}, grid, 1);
    cv::line(img, {area.x - 5, y}, {area.x, y}, black, 1);
    const std::string t = tick_label(v, ys);
    int base = 0;
    const cv::Size sz = cv::getTextSize(t, font, 0.42, 1, &base);
    cv::putText(img, t, {area.x - 8 - sz.width, y + 5}, font, 0.42, black, 1, cv::LINE_AA);
  }

  // Data, clipped to the plot area.
  cv::Mat canvas = img(area);
  auto local = [&](double x, double y) { return cv::Point(px(x) - area.x, py(y) - area.y); };
  for (const auto& s : series) {
    const std::size_t n = s.x.size();
    if (s.style == PlotSeries::Style::bars) {
      const double w = n > 1 ? (s.x[1] - s.x[0]) : 1.0;
      for (std::size_t i = 0; i < n; ++i) {
        if (!(s.y[i] > 0)) continue;
        cv::rectangle(canvas, local(s.x[i] - w / 2, s.y[i]), local(s.x[i] + w / 2, y0), s.color, cv::FILLED);
      }
      continue;
    }
    // A point without a value (NaN: eval's score without a reference) is a gap in the line, not a bridge.
    std::vector<cv::Point> pts;
    const auto draw_run = [&] {
      if (pts.size() == 1)  // a value between two gaps: a dot, not nothing
        cv::circle(canvas, pts[0], std::max(1, s.thickness), s.color, cv::FILLED, cv::LINE_AA);
      for (std::size_t i = 1; i < pts.size(); ++i) {
        if (s.dashed)
          dashed_line(canvas, pts[i - 1], pts[i], s.color, s.thickness);
        else
          cv::line(canvas, pts[i - 1], pts[i], s.color, s.thickness, cv::LINE_AA);
      }
      pts.clear();
    };
    for (std::size_t i = 0; i < n; ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) {
        draw_run();
        continue;
      }
      if (s.style == PlotSeries::Style::step && !pts.empty()) pts.push_back({local(s.x[i], 0).x, pts.back().y});
      pts.push_back(local(s.x[i], s.y[i]));
    }
    draw_run();
  }
  cv::rectangle(img, area, black, 1);

  // Labels and title.
  int base = 0;
  cv::Size sz = cv::getTextSize(o.x_label, font, 0.5, 1, &base);
  cv::putText(img, o.x_label, {area.x + (area.width - sz.width) / 2, o.height - 12}, font, 0.5, black, 1, cv::LINE_AA);
  sz = cv::getTextSize(o.y_label, font, 0.5, 1, &base);
  cv::Mat ylab(sz.height + base + 6, sz.width + 6, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::putText(ylab, o.y_label, {3, sz.height + 2}, font, 0.5, black, 1, cv::LINE_AA);
  cv::Mat rotated;
  cv::rotate(ylab, rotated, cv::ROTATE_90_COUNTERCLOCKWISE);
  const int ry = std::max(0, area.y + (area.height - rotated.rows) / 2);
  if (rotated.rows <= o.height - ry && rotated.cols < left)
    rotated.copyTo(img(cv::Rect(4, ry, rotated.cols, rotated.rows)));
  sz = cv::getTextSize(o.title, font, 0.6, 1, &base);
  cv::putText(img, o.title, {(o.width - sz.width) / 2, 26}, font, 0.6, black, 1, cv::LINE_AA);

  // Legend, top right inside the plot area.
  int lw = 0;
  for (const auto& s : series) lw = std::max(lw, cv::getTextSize(s.label, font, 0.45, 1, &base).width);
  if (lw > 0) {
    const int lh = 20 * static_cast<int>(series.size()) + 8;
    const cv::Rect box(area.x + area.width - lw - 54,
                       o.legend_bottom ? area.y + area.height - lh - 8 : area.y + 8, lw + 46, lh);
    cv::rectangle(img, box, cv::Scalar(255, 255, 255), cv::FILLED);
    cv::rectangle(img, box, cv::Scalar(160, 160, 160), 1);
    int y = box.y + 18;
    for (const auto& s : series) {
      if (s.style == PlotSeries::Style::bars)
        cv::rectangle(img, {box.x + 6, y - 9}, {box.x + 32, y + 1}, s.color, cv::FILLED);
      else if (s.dashed)
        dashed_line(img, {box.x + 6, y - 4}, {box.x + 32, y - 4}, s.color, s.thickness);
      else
        cv::line(img, {box.x + 6, y - 4}, {box.x + 32, y - 4}, s.color, s.thickness, cv::LINE_AA);
      cv::putText(img, s.label, {box.x + 38, y}, font, 0.45, black, 1, cv::LINE_AA);
      y += 20;
    }
  }
  return img;
}

}  // namespace evlife::render
