// Lays out a displayable frame: one or more views (active events by lifetime,
// fixed windows) upscaled by an integer factor, labelled like the paper's
// figures, with an optional lifetime legend and a caption (time and mode).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

#include "evlife/algo/active_event_map.h"
#include "evlife/render/fixed_window_map.h"
#include "evlife/render/frame_painter.h"
#include "evlife/render/frame_style.h"
#include "evlife/render/lifetime_colormap.h"

namespace evlife::render {

/// One panel of a frame.
struct View {
  bool lifetime = true;         ///< true: active events; false: fixed window
  std::int64_t window_us = 0;   ///< for fixed windows
  std::string label;            ///< drawn above the panel ("" = none)
};

/// "lifetime" | "window:<duration>" | "compare" (1 ms and 30 ms windows beside
/// the lifetime image, as paper Figs. 8, 13, 14). Throws std::invalid_argument.
std::vector<View> parse_view_mode(std::string_view mode);

/// The colouring the views show: a fixed window has no lifetime to colour by,
/// so `lifetime` asked of windows alone draws them plain (what captions say).
ColorMode color_drawn(ColorMode asked, const std::vector<View>& views) noexcept;

/// "30ms", "500us", "0.25s", "2.5" (bare number = seconds) -> microseconds.
/// Throws std::invalid_argument naming the text.
std::int64_t parse_duration_us(std::string_view text);

class FrameComposer {
 public:
  /// Throws std::invalid_argument for an empty view list, a bad scale or
  /// lifetime range.
  FrameComposer(std::vector<View> views, FrameStyle style, std::string mode_name);

  /// The frame at t_us. The caption shows caption_t_us (e.g. the time from
  /// the first event; default t_us). The image stays valid until the next call.
  const cv::Mat& compose(const ActiveEventMap& set, const FixedWindowMap& window,
                         std::int64_t t_us, std::optional<std::int64_t> caption_t_us = {});

  /// Size of every frame (fixed for a given sensor): what a video writer needs.
  cv::Size frame_size(SensorSize sensor) const;

  const std::vector<View>& views() const noexcept { return views_; }
  const FrameStyle& style() const noexcept { return style_; }

 private:
  bool has_legend() const noexcept;
  int label_height() const noexcept;

  std::vector<View> views_;
  FrameStyle style_;
  LifetimeColormap colormap_;
  std::string mode_name_;
  cv::Mat sensor_img_;
  cv::Mat scaled_;
  cv::Mat frame_;
  cv::Mat legend_;
};

}  // namespace evlife::render
