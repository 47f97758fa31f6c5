// Paints sensor-sized images (one pixel per sensor pixel, CV_8UC3 BGR or
// CV_8UC1 mask) of the active events or of a fixed window at time t.
// Cost O(sensor pixels); `out` is reused when it already has the right size,
// so painting frame after frame does not allocate.
#pragma once

#include <cstdint>
#include <string_view>

#include <opencv2/core.hpp>

#include "evlife/algo/active_event_map.h"
#include "evlife/render/fixed_window_map.h"
#include "evlife/render/frame_style.h"
#include "evlife/render/lifetime_colormap.h"

namespace evlife::render {

inline const cv::Vec3b kBackground{0, 0, 0};
inline const cv::Vec3b kPlain{255, 255, 255};
inline const cv::Vec3b kOn{80, 230, 80};
inline const cv::Vec3b kOff{255, 90, 255};

/// Events of `set` active at t_us (t_us >= set.last_fed_t_us()).
void paint_active(const ActiveEventMap& set, std::int64_t t_us, ColorMode mode,
                  const LifetimeColormap& colormap, cv::Mat& out);

/// Events of the window [t_us - window_us, t_us].
void paint_window(const FixedWindowMap& map, std::int64_t t_us, std::int64_t window_us,
                  ColorMode mode, cv::Mat& out);

/// 255 where active, else 0 (for metrics).
void active_mask(const ActiveEventMap& set, std::int64_t t_us, cv::Mat& out);
void window_mask(const FixedWindowMap& map, std::int64_t t_us, std::int64_t window_us,
                 cv::Mat& out);

}  // namespace evlife::render
