#include "evlife/render/frame_painter.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

namespace evlife::render {

ColorMode parse_color_mode(std::string_view name) {
  if (name == "lifetime") return ColorMode::lifetime;
  if (name == "polarity") return ColorMode::polarity;
  if (name == "plain") return ColorMode::plain;
  throw std::invalid_argument("unknown colour mode '" + std::string(name) +
                              "' (use lifetime, polarity or plain)");
}

std::string_view to_string(ColorMode mode) {
  switch (mode) {
    case ColorMode::lifetime: return "lifetime";
    case ColorMode::polarity: return "polarity";
    case ColorMode::plain: return "plain";
  }
  return "?";
}

namespace {
cv::Vec3b polarity_color(std::int8_t p) { return p > 0 ? kOn : kOff; }
}  // namespace

namespace {
template <ColorMode kMode>
void paint_active_rows(const ActiveEventMap& set, std::int64_t t_us, const LifetimeColormap& colormap,
                       cv::Mat& out) {
  // Rows are cleared with memset: kBackground is black.
  const SensorSize s = set.sensor();
  const std::int32_t* expire = set.expire_map().data();
  // Saturated into int32, so the per-pixel test is a 32-bit compare that
  // the compiler vectorizes: most pixels are inactive and cost one compare.
  const auto rel = static_cast<std::int32_t>(set.relative_time(t_us));
  constexpr int kChunk = 16;
  for (int y = 0; y < s.height; ++y) {
    auto* row = out.ptr<cv::Vec3b>(y);
    std::memset(static_cast<void*>(row), 0, static_cast<std::size_t>(s.width) * sizeof(cv::Vec3b));
    const std::int32_t* e = expire + static_cast<std::size_t>(y) * static_cast<std::size_t>(s.width);
    for (int x0 = 0; x0 < s.width; x0 += kChunk) {
      const int x1 = std::min(x0 + kChunk, s.width);
      bool any = false;
      for (int x = x0; x < x1; ++x) any |= rel < e[x];
      if (!any) continue;
      for (int x = x0; x < x1; ++x) {
        if (rel >= e[x]) continue;
        const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(s.width) +
                              static_cast<std::size_t>(x);
        if constexpr (kMode == ColorMode::lifetime) {
          row[x] = colormap.color(set.lifetime_us(i));
        } else if constexpr (kMode == ColorMode::polarity) {
          row[x] = polarity_color(set.polarity(i));
        } else {
          row[x] = kPlain;
        }
      }
    }
  }
}
}  // namespace

void paint_active(const ActiveEventMap& set, std::int64_t t_us, ColorMode mode,
                  const LifetimeColormap& colormap, cv::Mat& out) {
  const SensorSize s = set.sensor();
  out.create(s.height, s.width, CV_8UC3);
  switch (mode) {
    case ColorMode::lifetime: paint_active_rows<ColorMode::lifetime>(set, t_us, colormap, out); break;
    case ColorMode::polarity: paint_active_rows<ColorMode::polarity>(set, t_us, colormap, out); break;
    case ColorMode::plain: paint_active_rows<ColorMode::plain>(set, t_us, colormap, out); break;
  }
}

void paint_window(const FixedWindowMap& map, std::int64_t t_us, std::int64_t window_us,
                  ColorMode mode, cv::Mat& out) {
  const SensorSize s = map.sensor();
  out.create(s.height, s.width, CV_8UC3);
  const auto w = map.relative_window(t_us, window_us);
  // Bounds within int32 (relative_window saturates), so the per-pixel test
  // is two 32-bit compares that vectorize; rows are cleared with memset.
  const auto lo = static_cast<std::int32_t>(w.lo);
  const auto hi = static_cast<std::int32_t>(w.hi);
  const std::int32_t* last = map.last_map().data();
  constexpr int kChunk = 16;
  for (int y = 0; y < s.height; ++y) {
    auto* row = out.ptr<cv::Vec3b>(y);
    std::memset(static_cast<void*>(row), 0, static_cast<std::size_t>(s.width) * sizeof(cv::Vec3b));
    const std::size_t row0 = static_cast<std::size_t>(y) * static_cast<std::size_t>(s.width);
    const std::int32_t* l = last + row0;
    for (int x0 = 0; x0 < s.width; x0 += kChunk) {
      const int x1 = std::min(x0 + kChunk, s.width);
      bool any = false;
      for (int x = x0; x < x1; ++x) any |= (l[x] >= lo) & (l[x] <= hi);
      if (!any) continue;
      for (int x = x0; x < x1; ++x) {
        if (l[x] < lo || l[x] > hi) continue;
        row[x] = mode == ColorMode::polarity ? polarity_color(map.polarity(row0 + static_cast<std::size_t>(x))) : kPlain;
      }
    }
  }
}

void active_mask(const ActiveEventMap& set, std::int64_t t_us, cv::Mat& out) {
  const SensorSize s = set.sensor();
  out.create(s.height, s.width, CV_8UC1);
  const std::int32_t* expire = set.expire_map().data();
  const std::int64_t rel = set.relative_time(t_us);
  std::size_t i = 0;
  for (int y = 0; y < s.height; ++y) {
    auto* row = out.ptr<std::uint8_t>(y);
    for (int x = 0; x < s.width; ++x, ++i) row[x] = rel < expire[i] ? 255 : 0;
  }
}

void window_mask(const FixedWindowMap& map, std::int64_t t_us, std::int64_t window_us,
                 cv::Mat& out) {
  const SensorSize s = map.sensor();
  out.create(s.height, s.width, CV_8UC1);
  const auto w = map.relative_window(t_us, window_us);
  std::size_t i = 0;
  for (int y = 0; y < s.height; ++y) {
    auto* row = out.ptr<std::uint8_t>(y);
    for (int x = 0; x < s.width; ++x, ++i) row[x] = map.is_active_rel(i, w) ? 255 : 0;
  }
}

}  // namespace evlife::render
