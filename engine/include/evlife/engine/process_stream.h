// The offline read -> estimate -> write loop of `evlife process` (and of any
// host that wants a file's augmented events without the engine's threads):
// batch by batch in constant memory; on a read or write fault everything
// before it is written and flushed, and the fault is returned, never thrown.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>

#include "evlife/algo/event.h"
#include "evlife/algo/lifetime_estimator.h"
#include "evlife/io/augmented_event_writer.h"
#include "evlife/io/event_reader.h"

namespace evlife::engine {

struct ProcessStreamResult {
  std::uint64_t events_written = 0;
  double estimator_s = 0.0;                 ///< time inside the estimator
  std::optional<std::string> input_fault;   ///< the reader's error, if it stopped the loop
  std::optional<std::string> output_fault;  ///< the writer's error (also on close)
  bool stopped = false;                     ///< `stop` was seen
};

/// Reads `reader` to its end, estimates every event and writes it, in input
/// order; `on_batch` sees each written batch (summaries, progress); `stop`,
/// when set (e.g. by a signal handler), ends the loop after the current batch.
/// Closes the writer.
ProcessStreamResult process_stream(io::EventReader& reader, LifetimeEstimator& estimator,
                                   io::AugmentedEventWriter& writer,
                                   const std::function<void(std::span<const AugmentedEvent>)>& on_batch,
                                   const std::atomic<bool>* stop = nullptr,
                                   std::size_t batch_events = std::size_t{1} << 16);

}  // namespace evlife::engine
