// Minimal 2-D plots drawn with OpenCV (the evaluation figures): axes with
// 1-2-5 ticks, axis labels with units, a title and a legend.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace evlife::render {

struct PlotSeries {
  enum class Style { line, step, bars };
  std::string label;
  std::vector<double> x;
  std::vector<double> y;
  cv::Scalar color{200, 80, 0};
  Style style = Style::line;
  int thickness = 2;
  bool dashed = false;
};

struct PlotOptions {
  std::string title;
  std::string x_label;  ///< with unit, e.g. "lifetime [ms]"
  std::string y_label;
  int width = 760;
  int height = 460;
  std::optional<double> x_min, x_max, y_min, y_max;  ///< default: data range
  bool legend_bottom = false;  ///< legend in the bottom-right corner instead of top-right
};

/// Throws std::invalid_argument when a series' x and y differ in size.
cv::Mat draw_plot(const PlotOptions& options, const std::vector<PlotSeries>& series);

/// Distinct colours (BGR) for series k.
cv::Scalar series_color(int k);

}  // namespace evlife::render
