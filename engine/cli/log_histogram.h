// Constant-memory histogram with logarithmic bins, for percentiles of
// quantities spanning decades (lifetimes, prediction errors). Relative
// resolution: one bin = 10^(1/bins_per_decade) (100/decade: ±1.2%).
#pragma once

#include <cstdint>
#include <vector>

namespace evlife::cli {

class LogHistogram {
 public:
  /// Bins cover [min_value, max_value); smaller values land in an underflow
  /// bin, larger in an overflow bin (both counted). min_value > 0.
  LogHistogram(double min_value, double max_value, int bins_per_decade);

  void add(double value) noexcept;  ///< NaN is ignored

  std::uint64_t count() const noexcept { return count_; }
  std::uint64_t underflow() const noexcept { return bins_.front(); }
  std::uint64_t overflow() const noexcept { return bins_.back(); }

  /// Value below which a share q in [0, 1] of the samples lie: the geometric
  /// centre of the bin holding it (min_value / max_value for the outer bins).
  /// NaN when empty.
  double percentile(double q) const noexcept;

  /// Share of samples below `value` (to bin resolution).
  double share_below(double value) const noexcept;

 private:
  double min_value_;
  double max_value_;
  double bins_per_decade_;
  std::uint64_t count_ = 0;
  std::vector<std::uint64_t> bins_;  // [underflow, n regular bins..., overflow]
};

}  // namespace evlife::cli
