// The project's one value histogram: constant memory (any recording length),
// bins set at run time and allocated once, plus counts below and above the
// range. Two bin scales:
//  - linear: equal bins over [lo, lo + bins * width), for the paper's plots
//    (0.2 ms lifetime bins, Figs. 9-10); read with quantile() (upper bin
//    edge) and cdf_at_bin_end();
//  - log: bins_per_decade bins per factor 10 over [min, max), for the CLI
//    summary's percentiles of quantities spanning decades (lifetimes,
//    prediction errors; 100/decade: ±1.2 %); read with percentile()
//    (nearest rank, bin centre) and share_below().
// Single-threaded. The engine's latency histogram (engine/latency_histogram.h)
// stays a separate class on purpose: it is recorded in a running engine's
// per-event path and read by another thread meanwhile, so it is atomic,
// integer nanoseconds, a fixed std::array with no constructor work.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace evlife::render {

class Histogram {
 public:
  /// Linear bins: `bins` bins of `bin_width` from `lo`.
  /// Throws std::invalid_argument unless bin_width > 0, bins >= 1, lo finite.
  Histogram(double lo, double bin_width, std::size_t bins);

  /// Log bins covering [min_value, max_value), bins_per_decade per factor 10
  /// (the last bin may end above max_value; values >= max_value count above).
  /// Throws std::invalid_argument unless 0 < min_value < max_value (finite)
  /// and bins_per_decade >= 1.
  static Histogram log_bins(double min_value, double max_value, int bins_per_decade);

  void add(double v) noexcept {
    if (!(v == v)) return;  // NaN: not a value
    if (log_) {
      add_log(v);
    } else if (v < lo_) {
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

  bool is_log() const noexcept { return log_; }
  double lo() const noexcept { return lo_; }
  /// Linear: the bin width; log: bins per decade.
  double bin_width() const noexcept { return width_; }
  std::size_t bins() const noexcept { return counts_.size(); }
  double bin_start(std::size_t k) const noexcept;
  /// Middle of bin k (geometric middle for log bins).
  double bin_centre(std::size_t k) const noexcept;
  std::uint64_t count(std::size_t k) const noexcept { return counts_[k]; }
  std::uint64_t below() const noexcept { return below_; }
  std::uint64_t above() const noexcept { return above_; }
  std::uint64_t total() const noexcept { return total_; }

  /// Share of all values < bin_start(k + 1) (the CDF at the bin's upper edge).
  double cdf_at_bin_end(std::size_t k) const noexcept;
  /// Value below which a share q of all values lie, at bin resolution
  /// (upper bin edge); the range end when the quantile is above it; NaN when empty.
  double quantile(double q) const noexcept;

  /// Nearest-rank percentile q in [0, 1]: the centre of the bin holding the
  /// sample of rank ceil(q * total) (lo() / the range end for the outer
  /// counts). NaN when empty.
  double percentile(double q) const noexcept;
  /// Share of all values below `v`, to bin resolution (whole bins whose
  /// upper edge is <= v). NaN when empty.
  double share_below(double v) const noexcept;

 private:
  Histogram() = default;
  void add_log(double v) noexcept;
  double range_end() const noexcept;
  double position(double v) const noexcept;  // v in bin units from lo

  bool log_ = false;
  double lo_ = 0.0;
  double width_ = 1.0;  // linear: bin width; log: bins per decade
  double hi_ = 0.0;     // log: max_value (values >= it count above)
  std::vector<std::uint64_t> counts_;
  std::uint64_t below_ = 0;
  std::uint64_t above_ = 0;
  std::uint64_t total_ = 0;
};

}  // namespace evlife::render
