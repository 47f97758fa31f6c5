#include "log_histogram.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace evlife::cli {

LogHistogram::LogHistogram(double min_value, double max_value, int bins_per_decade)
    : min_value_(min_value), max_value_(max_value), bins_per_decade_(bins_per_decade) {
  const auto regular =
      static_cast<std::size_t>(std::ceil(std::log10(max_value / min_value) * bins_per_decade_));
  bins_.assign(regular + 2, 0);  // sized once; add() never allocates
}

void LogHistogram::add(double value) noexcept {
  if (std::isnan(value)) return;
  std::size_t bin;
  if (value < min_value_) {
    bin = 0;
  } else if (value >= max_value_) {
    bin = bins_.size() - 1;
  } else {
    const double pos = std::log10(value / min_value_) * bins_per_decade_;
    bin = 1 + std::min(static_cast<std::size_t>(pos), bins_.size() - 3);
  }
  ++bins_[bin];
  ++count_;
}

double LogHistogram::percentile(double q) const noexcept {
  if (count_ == 0) return std::numeric_limits<double>::quiet_NaN();
  // Rank of the sample asked for, 1-based, as in the nearest-rank method.
  const auto rank = static_cast<std::uint64_t>(
      std::max(1.0, std::ceil(q * static_cast<double>(count_))));
  std::uint64_t seen = 0;
  for (std::size_t b = 0; b < bins_.size(); ++b) {
    seen += bins_[b];
    if (seen < rank) continue;
    if (b == 0) return min_value_;
    if (b == bins_.size() - 1) return max_value_;
    const double centre = (static_cast<double>(b) - 1.0 + 0.5) / bins_per_decade_;
    return min_value_ * std::pow(10.0, centre);
  }
  return max_value_;
}

double LogHistogram::share_below(double value) const noexcept {
  if (count_ == 0) return std::numeric_limits<double>::quiet_NaN();
  if (value >= max_value_) {
    return static_cast<double>(count_ - bins_.back()) / static_cast<double>(count_);
  }
  std::uint64_t below = 0;
  if (value >= min_value_) {
    below = bins_[0];  // everything under min_value
    const double edge_pos = std::log10(value / min_value_) * bins_per_decade_;
    for (std::size_t b = 1; b + 1 < bins_.size(); ++b) {
      if (static_cast<double>(b) > edge_pos) break;  // regular bin b ends at edge b
      below += bins_[b];
    }
  }
  return static_cast<double>(below) / static_cast<double>(count_);
}

}  // namespace evlife::cli
