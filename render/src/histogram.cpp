#include "evlife/render/histogram.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace evlife::render {

Histogram::Histogram(double lo, double bin_width, std::size_t bins)
    : lo_(lo), width_(bin_width), counts_(bins, 0) {
  if (!(bin_width > 0.0) || bins == 0 || !std::isfinite(lo)) {
    throw std::invalid_argument("Histogram: need bin_width > 0 and at least one bin");
  }
}

Histogram Histogram::log_bins(double min_value, double max_value, int bins_per_decade) {
  if (!(min_value > 0.0) || !(max_value > min_value) || !std::isfinite(max_value) || bins_per_decade < 1) {
    throw std::invalid_argument("Histogram: log bins need 0 < min_value < max_value and bins_per_decade >= 1");
  }
  Histogram h;
  h.log_ = true;
  h.lo_ = min_value;
  h.hi_ = max_value;
  h.width_ = bins_per_decade;
  const auto regular = static_cast<std::size_t>(std::ceil(std::log10(max_value / min_value) * h.width_));
  h.counts_.assign(regular, 0);  // sized once; add() never allocates
  return h;
}

void Histogram::add_log(double v) noexcept {
  if (v < lo_) {
    ++below_;
  } else if (v >= hi_) {
    ++above_;
  } else {
    const double pos = std::log10(v / lo_) * width_;
    ++counts_[std::min(static_cast<std::size_t>(pos), counts_.size() - 1)];
  }
}

double Histogram::bin_start(std::size_t k) const noexcept {
  if (log_) return lo_ * std::pow(10.0, static_cast<double>(k) / width_);
  return lo_ + width_ * static_cast<double>(k);
}

double Histogram::bin_centre(std::size_t k) const noexcept {
  if (log_) return lo_ * std::pow(10.0, (static_cast<double>(k) + 0.5) / width_);
  return bin_start(k) + 0.5 * width_;
}

double Histogram::range_end() const noexcept { return log_ ? hi_ : bin_start(counts_.size()); }

double Histogram::position(double v) const noexcept {
  return log_ ? std::log10(v / lo_) * width_ : (v - lo_) / width_;
}

double Histogram::cdf_at_bin_end(std::size_t k) const noexcept {
  if (total_ == 0) return 0.0;
  std::uint64_t n = below_;
  for (std::size_t i = 0; i <= k && i < counts_.size(); ++i) n += counts_[i];
  return static_cast<double>(n) / static_cast<double>(total_);
}

double Histogram::quantile(double q) const noexcept {
  if (total_ == 0) return std::numeric_limits<double>::quiet_NaN();
  const double target = q * static_cast<double>(total_);
  double n = static_cast<double>(below_);
  if (n >= target && below_ > 0) return lo_;
  for (std::size_t i = 0; i < counts_.size(); ++i) {
    n += static_cast<double>(counts_[i]);
    if (n >= target) return bin_start(i + 1);
  }
  return bin_start(counts_.size());
}

double Histogram::percentile(double q) const noexcept {
  if (total_ == 0) return std::numeric_limits<double>::quiet_NaN();
  // Rank of the sample asked for, 1-based, as in the nearest-rank method.
  const auto rank = static_cast<std::uint64_t>(std::max(1.0, std::ceil(q * static_cast<double>(total_))));
  std::uint64_t seen = below_;
  if (seen >= rank) return lo_;
  for (std::size_t k = 0; k < counts_.size(); ++k) {
    seen += counts_[k];
    if (seen >= rank) return bin_centre(k);
  }
  return range_end();
}

double Histogram::share_below(double v) const noexcept {
  if (total_ == 0) return std::numeric_limits<double>::quiet_NaN();
  if (v >= range_end()) return static_cast<double>(total_ - above_) / static_cast<double>(total_);
  std::uint64_t n = 0;
  if (v >= lo_) {
    n = below_;  // everything under lo
    const double edge_pos = position(v);
    for (std::size_t k = 0; k < counts_.size(); ++k) {
      if (static_cast<double>(k + 1) > edge_pos) break;  // bin k ends at edge k + 1
      n += counts_[k];
    }
  }
  return static_cast<double>(n) / static_cast<double>(total_);
}

}  // namespace evlife::render
