#include "evlife/engine/process_stream.h"

#include <vector>

#include "evlife/io/uninitialized_array.h"

#include "evlife/io/estimating_reader.h"

namespace evlife::engine {

ProcessStreamResult process_stream(io::EventReader& reader, LifetimeEstimator& estimator,
                                   io::AugmentedEventWriter& writer,
                                   const std::function<void(std::span<const AugmentedEvent>)>& on_batch,
                                   const std::atomic<bool>* stop, std::size_t batch_events) {
  ProcessStreamResult r;
  io::EstimatingReader estimating(reader, estimator, batch_events);
  io::UninitializedArray<AugmentedEvent> out(batch_events);
  while (!(stop && stop->load(std::memory_order_relaxed))) {
    std::size_t n = 0;
    try {
      n = estimating.read(out.span());
    } catch (const io::ReadError& e) {
      r.input_fault = e.what();
      break;
    }
    if (n == 0) break;
    const std::span<const AugmentedEvent> batch(out.data(), n);
    try {
      writer.write(batch);
    } catch (const io::WriteError& e) {
      r.output_fault = e.what();
      break;
    }
    r.events_written += n;
    if (on_batch) on_batch(batch);
  }
  r.estimator_s = estimating.estimator_s();
  r.stopped = stop && stop->load(std::memory_order_relaxed);
  try {
    writer.close();  // flushes: everything before a fault reaches the disk
  } catch (const io::WriteError& e) {
    if (!r.output_fault) r.output_fault = e.what();
  }
  return r;
}

}  // namespace evlife::engine
