// Fixed-bin histogram with constant memory (evaluation plots of any
// recording length): equal bins over [lo, lo + bins * width), plus counts
// below and above, and quantiles / a cumulative distribution from the bins.
// Linear bins for the paper's plots (0.2 ms lifetime bins, Figs. 9-10); the
// CLI's summary percentiles use log bins (engine/cli/log_histogram.h; the two
// could share one class with a bin scale, not done yet); the engine's latency
// histogram is a different kind (atomic, per event: latency_histogram.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace evlife::render {

class Histogram {
 public:
  /// Throws std::invalid_argument unless bin_width > 0 and bins >= 1.
  Histogram(double lo, double bin_width, std::size_t bins);

  void add(double v) noexcept {
    if (!(v == v)) return;  // NaN: not a value
    if (v < lo_) {
      ++below_;
    } else {
      const double k = (v - lo_) / width_;
      if (k >= static_cast<double>(counts_.size()))
        ++above_;
      else
        ++counts_[static_cast<std::size_t>(k)];
    }
    ++total_;
  }

  double lo() const noexcept { return lo_; }
  double bin_width() const noexcept { return width_; }
  std::size_t bins() const noexcept { return counts_.size(); }
  double bin_start(std::size_t k) const noexcept { return lo_ + width_ * static_cast<double>(k); }
  double bin_centre(std::size_t k) const noexcept { return bin_start(k) + 0.5 * width_; }
  std::uint64_t count(std::size_t k) const noexcept { return counts_[k]; }
  std::uint64_t below() const noexcept { return below_; }
  std::uint64_t above() const noexcept { return above_; }
  std::uint64_t total() const noexcept { return total_; }

  /// Share of all values < bin_start(k + 1) (the CDF at the bin's upper edge).
  double cdf_at_bin_end(std::size_t k) const noexcept;
  /// Value below which a share q of all values lie, at bin resolution
  /// (upper bin edge); the range end when the quantile is above it; NaN when empty.
  double quantile(double q) const noexcept;

 private:
  double lo_;
  double width_;
  std::vector<std::uint64_t> counts_;
  std::uint64_t below_ = 0;
  std::uint64_t above_ = 0;
  std::uint64_t total_ = 0;
};

}  // namespace evlife::render
