// A worker stage: runs its own LifetimeEstimator over every batch the router
// sends it (its tiles plus their margin), keeps the outputs of the events it
// owns, and passes the batch to the merger. Its result depends only on its
// own ordered input, hence the same bit for bit whatever the scheduling.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include "evlife/algo/lifetime_estimator.h"
#include "evlife/engine/pipeline_state.h"
#include "evlife/engine/step_result.h"

namespace evlife::engine {

class TileWorker {
 public:
  TileWorker(PipelineState& state, int worker);

  /// Processes at most one batch, or `events` of it after publish_every().
  /// Never waits, allocates or throws.
  StepResult step() noexcept;

  /// Steps of at most `events` events (call from the worker's thread before
  /// stepping): a batch longer than that is handed to the merger before it
  /// is processed and its outputs are published after each step, so that
  /// the merge can deliver a packet's first events while the rest are
  /// estimated (Engine::run, policy drop: latency). Default: whole batches,
  /// one hand-off each (throughput; and hand-stepped pipelines, where the
  /// router's chunk per round must find the worker's previous one done).
  void publish_every(std::size_t events) noexcept { step_events_ = events == 0 ? 1 : events; }

  /// Engine::run's publish_every() for live runs (policy drop): ~10-15 us of
  /// estimation per step at 0.3-0.45 us/event.
  static constexpr std::size_t kLiveStepEvents = 32;

  const LifetimeEstimator& estimator() const noexcept { return estimator_; }
  /// No batch queued for it or being processed (from the thread that steps
  /// the whole pipeline: Pipeline::reset_estimators).
  bool idle() const noexcept { return batch_ == nullptr && channel_.in.size_approx() == 0; }
  void reset_estimator() noexcept { estimator_.reset(); }

 private:
  PipelineState& state_;
  WorkerChannel& channel_;
  LifetimeEstimator estimator_;
  std::unique_ptr<moodycamel::ProducerToken> out_token_;
  std::unique_ptr<moodycamel::ProducerToken> free_token_;
  std::size_t step_events_ = SIZE_MAX;  // events per step (publish_every)
  WorkBatch* batch_ = nullptr;     // batch being processed, across steps
  std::size_t pos_ = 0;            // its next event
  std::size_t kept_ = 0;           // its outputs written so far
  bool published_early_ = false;   // handed to the merger before it was processed
  bool finished_ = false;
};

}  // namespace evlife::engine
