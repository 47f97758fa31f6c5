// Colour of an event by its lifetime, as in the paper's figures: short
// lifetimes (fast edges) blue, long lifetimes (slow edges) red. Log scale,
// because lifetimes of one scene easily span two decades.
#pragma once

#include <array>
#include <bit>
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace evlife::render {

/// A legend tick's label: "0.05 ms", "20 ms", "100 s" (seconds from 1 s on).
std::string lifetime_tick_label(double lifetime_us);

class LifetimeColormap {
 public:
  /// Lifetimes at or below min_us get the first colour, at or above max_us
  /// the last. Throws std::invalid_argument unless 0 < min_us < max_us.
  LifetimeColormap(double min_us, double max_us);
  /// 0.3 ms .. 30 ms: DVS128 scenes at walking to flipping speeds.
  LifetimeColormap() : LifetimeColormap(300.0, 30000.0) {}

  cv::Vec3b color(float lifetime_us) const noexcept {
    return lut_[static_cast<std::size_t>(fast_bin(lifetime_us))];
  }
  /// 0..255 position of a lifetime on the scale (exact log).
  int bin(float lifetime_us) const noexcept;
  /// Same from a table indexed by the float's exponent and top 8 mantissa
  /// bits (1/256 octave resolution, no log per pixel): differs from bin()
  /// by at most one step.
  int fast_bin(float lifetime_us) const noexcept {
    if (!(lifetime_us > min_f_)) return 0;
    if (!(lifetime_us < max_f_)) return 255;
    const std::uint32_t key = std::bit_cast<std::uint32_t>(lifetime_us) >> 15;
    return fast_table_[key - base_key_];
  }

  double min_us() const noexcept { return min_us_; }
  double max_us() const noexcept { return max_us_; }

  /// A vertical colour bar with tick labels in ms, `height` pixels tall,
  /// titled "lifetime": the legend drawn next to lifetime images.
  /// At least kLegendMinHeight rows, whatever `height` asks.
  cv::Mat legend(int height) const;
  static constexpr int kLegendMinHeight = 80;

 private:
  double min_us_;
  double max_us_;
  double log_min_;
  double inv_log_span_;
  std::array<cv::Vec3b, 256> lut_{};
  float min_f_;
  float max_f_;
  std::uint32_t base_key_;
  std::vector<std::uint8_t> fast_table_;
};

}  // namespace evlife::render
