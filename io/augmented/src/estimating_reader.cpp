#include "evlife/io/estimating_reader.h"

#include <algorithm>
#include <chrono>

namespace evlife::io {

EstimatingReader::EstimatingReader(EventReader& reader, LifetimeEstimator& estimator, std::size_t batch_events)
    : reader_(reader), estimator_(estimator), raw_(std::max<std::size_t>(batch_events, 1)) {}

std::size_t EstimatingReader::read(std::span<AugmentedEvent> out) {
  const std::size_t want = std::min(out.size(), raw_.size());
  const std::size_t n = reader_.read(std::span<Event>(raw_.data(), want));
  if (n == 0) return 0;
  const auto t0 = std::chrono::steady_clock::now();
  estimator_.process(std::span<const Event>(raw_.data(), n), out.first(n));
  estimator_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return n;
}

}  // namespace evlife::io
