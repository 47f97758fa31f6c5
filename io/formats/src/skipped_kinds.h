// Private: per-kind counts of the records a reader skips (frames, IMU
// samples, triggers, ...). The kinds are fixed when the reader is built, so
// counting never allocates; skipped_record_kinds() lists the kinds seen.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <string_view>
#include <vector>

#include "evlife/io/event_reader.h"

namespace evlife::io::detail {

template <std::size_t N>
class SkippedKinds {
 public:
  explicit constexpr SkippedKinds(const std::array<std::string_view, N>& names) : names_(names) {}

  void add(std::size_t kind, std::uint64_t n = 1) noexcept { counts_[kind] += n; }
  std::uint64_t count(std::size_t kind) const noexcept { return counts_[kind]; }
  std::uint64_t total() const noexcept {
    return std::accumulate(counts_.begin(), counts_.end(), std::uint64_t{0});
  }
  /// The kinds with a non-zero count, in table order.
  std::vector<SkippedKindCount> seen() const {
    std::vector<SkippedKindCount> out;
    for (std::size_t k = 0; k < N; ++k)
      if (counts_[k] > 0) out.push_back({names_[k], counts_[k]});
    return out;
  }

 private:
  std::array<std::string_view, N> names_;
  std::array<std::uint64_t, N> counts_{};
};

}  // namespace evlife::io::detail
