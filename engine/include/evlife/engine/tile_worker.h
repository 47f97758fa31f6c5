// A worker stage: runs its own LifetimeEstimator over every batch the router
// sends it (its tiles plus their margin), keeps the outputs of the events it
// owns, and passes the batch to the merger. Its result depends only on its
// own ordered input, hence the same bit for bit whatever the scheduling.
#pragma once

#include <memory>

#include "evlife/algo/lifetime_estimator.h"
#include "evlife/engine/pipeline_state.h"
#include "evlife/engine/step_result.h"

namespace evlife::engine {

class TileWorker {
 public:
  TileWorker(PipelineState& state, int worker);

  /// Processes at most one batch. Never waits, allocates or throws.
  StepResult step() noexcept;

  const LifetimeEstimator& estimator() const noexcept { return estimator_; }

 private:
  PipelineState& state_;
  WorkerChannel& channel_;
  LifetimeEstimator estimator_;
  std::unique_ptr<moodycamel::ProducerToken> out_token_;
  std::unique_ptr<moodycamel::ProducerToken> free_token_;
  bool finished_ = false;
};

}  // namespace evlife::engine
