// The one read -> estimate step: a raw EventReader's events augmented by a
// LifetimeEstimator, batch by batch, in input order. engine::process_stream
// (`evlife process`) and render's on-the-fly source (`evlife render` / `eval`
// on a raw recording) both read through it, so the two cannot drift apart.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "evlife/algo/event.h"
#include "evlife/algo/lifetime_estimator.h"
#include "evlife/io/event_reader.h"
#include "evlife/io/uninitialized_array.h"

namespace evlife::io {

class EstimatingReader {
 public:
  /// Neither `reader` nor `estimator` is owned; both outlive this. The raw
  /// buffer (batch_events events, at least 1) is allocated here, once.
  EstimatingReader(EventReader& reader, LifetimeEstimator& estimator, std::size_t batch_events);

  /// Reads up to min(out.size(), batch_events) events, estimates them into
  /// `out` and returns how many; 0 at the end. A read error throws ReadError
  /// as the reader does: the events before it were returned by earlier calls.
  std::size_t read(std::span<AugmentedEvent> out);

  /// Seconds spent inside the estimator so far (timed per batch).
  double estimator_s() const noexcept { return estimator_s_; }
  const EventReader& reader() const noexcept { return reader_; }
  const LifetimeEstimator& estimator() const noexcept { return estimator_; }

 private:
  EventReader& reader_;
  LifetimeEstimator& estimator_;
  UninitializedArray<Event> raw_;
  double estimator_s_ = 0.0;
};

}  // namespace evlife::io
