#include "evlife/render/frame_painter.h"

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

void paint_active(const ActiveEventSet& set, std::int64_t t_us, ColorMode mode,
                  const LifetimeColormap& colormap, cv::Mat& out) {
  const SensorSize s = set.sensor();
  out.create(s.height, s.width, CV_8UC3);
  const auto expire = set.expire_map_us();
  std::size_t i = 0;
  for (int y = 0; y < s.height; ++y) {
    auto* row = out.ptr<cv::Vec3b>(y);
    for (int x = 0; x < s.width; ++x, ++i) {
      if (t_us >= expire[i]) {
        row[x] = kBackground;
        continue;
      }
      switch (mode) {
        case ColorMode::lifetime: row[x] = colormap.color(set.lifetime_us(i)); break;
        case ColorMode::polarity: row[x] = polarity_color(set.polarity(i)); break;
        case ColorMode::plain: row[x] = kPlain; break;
      }
    }
  }
}

void paint_window(const FixedWindowMap& map, std::int64_t t_us, std::int64_t window_us,
                  ColorMode mode, cv::Mat& out) {
  const SensorSize s = map.sensor();
  out.create(s.height, s.width, CV_8UC3);
  std::size_t i = 0;
  for (int y = 0; y < s.height; ++y) {
    auto* row = out.ptr<cv::Vec3b>(y);
    for (int x = 0; x < s.width; ++x, ++i) {
      if (!map.is_active(i, t_us, window_us))
        row[x] = kBackground;
      else
        row[x] = mode == ColorMode::polarity ? polarity_color(map.polarity(i)) : kPlain;
    }
  }
}

void active_mask(const ActiveEventSet& set, std::int64_t t_us, cv::Mat& out) {
  const SensorSize s = set.sensor();
  out.create(s.height, s.width, CV_8UC1);
  const auto expire = set.expire_map_us();
  std::size_t i = 0;
  for (int y = 0; y < s.height; ++y) {
    auto* row = out.ptr<std::uint8_t>(y);
    for (int x = 0; x < s.width; ++x, ++i) row[x] = t_us < expire[i] ? 255 : 0;
  }
}

void window_mask(const FixedWindowMap& map, std::int64_t t_us, std::int64_t window_us,
                 cv::Mat& out) {
  const SensorSize s = map.sensor();
  out.create(s.height, s.width, CV_8UC1);
  std::size_t i = 0;
  for (int y = 0; y < s.height; ++y) {
    auto* row = out.ptr<std::uint8_t>(y);
    for (int x = 0; x < s.width; ++x, ++i) row[x] = map.is_active(i, t_us, window_us) ? 255 : 0;
  }
}

}  // namespace evlife::render
