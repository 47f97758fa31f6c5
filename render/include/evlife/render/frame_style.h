// How a frame looks: colour, scale, caption, legend, lifetime colour range.
// Plain values, no OpenCV: the engine's public headers take a FrameStyle.
#pragma once

#include <algorithm>
#include <string_view>

namespace evlife::render {

enum class ColorMode {
  lifetime,  ///< colour by lifetime (LifetimeColormap); windows have none: drawn plain
  polarity,  ///< ON green, OFF magenta
  plain,     ///< white
};

/// "lifetime", "polarity", "plain"; throws std::invalid_argument otherwise.
ColorMode parse_color_mode(std::string_view name);
std::string_view to_string(ColorMode mode);

struct FrameStyle {
  static constexpr int kMaxScale = 32;
  /// The largest end of the lifetime colour scale a user may give, in ms
  /// (`render --lifetime-range`, evlife.frame's lifetime_range_ms).
  static constexpr double kMaxLifetimeRangeMs = 1e9;

  /// The upscaling that brings the larger sensor side near `target_px`, within
  /// 1..kMaxScale (a sensor of a few pixels would otherwise ask for more).
  static constexpr int scale_to_fit(int width, int height, int target_px) noexcept {
    return std::clamp(target_px / std::max({width, height, 1}), 1, kMaxScale);
  }
  /// The upscaling of `evlife render`, `run --frames` and evlife.frame when
  /// none is given: the larger side near 512 px.
  static constexpr int default_scale(int width, int height) noexcept { return scale_to_fit(width, height, 512); }

  ColorMode color = ColorMode::lifetime;
  int scale = 4;          ///< integer upscaling, 1..kMaxScale (nearest neighbour: pixels stay crisp)
  bool caption = true;    ///< time and mode under the image
  bool legend = true;     ///< lifetime colour bar (only drawn when colouring by lifetime)
  /// Lifetime colour scale (log): at or below min the first colour, at or
  /// above max the last; 0 < min < max (checked by FrameComposer).
  double lifetime_min_us = 300.0;
  double lifetime_max_us = 30000.0;
};

}  // namespace evlife::render
