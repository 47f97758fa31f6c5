#include "evlife/render/histogram.h"

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

}  // namespace evlife::render
