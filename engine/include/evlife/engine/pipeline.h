// The engine's stages wired together, without threads: Router, one
// TileWorker per worker, Merger, over one PipelineState. Tests drive it with
// step_all(); Engine runs each stage's step() on its own thread; a host's
// scheduler (a flight-software work queue) calls run_for() from its own loop
// — README: "The pipeline inside your scheduler".
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "evlife/engine/augmented_sink.h"
#include "evlife/engine/aux_stage.h"
#include "evlife/engine/engine_stats.h"
#include "evlife/engine/event_source.h"
#include "evlife/engine/merge_role.h"
#include "evlife/engine/merger.h"
#include "evlife/engine/pipeline_state.h"
#include "evlife/engine/router.h"
#include "evlife/engine/tile_worker.h"

namespace evlife::engine {

/// What one Pipeline::run_for() call did.
struct PipelineRunReport {
  bool finished = false;          ///< the stream ended and everything was handed to the sink
  bool budget_exhausted = false;  ///< stopped at the time budget with work left (call again)
  int rounds = 0;                 ///< rounds of step_all() made
  std::int64_t elapsed_ns = 0;    ///< time spent in the call
  std::uint64_t events_out = 0;   ///< events handed to the sink during the call
};

class Pipeline {
 public:
  /// Sizes every pool and estimator for the source's sensor. `sink` may be
  /// null. Throws std::invalid_argument (naming the field) on bad options.
  Pipeline(EventSource& source, AugmentedSink* sink, const EngineOptions& options);

  /// Adds a stage off the data path (the render stage, fed by
  /// state().render_tap). Before running; it must outlive the pipeline's run.
  void attach(AuxStage& stage) { aux_.push_back(&stage); }
  const std::vector<AuxStage*>& aux_stages() const noexcept { return aux_; }

  /// One step of every stage, in pipeline order; true once all finished.
  bool step_all() noexcept;

  /// Runs step_all() until the end of the stream (single thread).
  void run_inline() noexcept {
    while (!step_all()) {
    }
  }

  /// For a host's scheduler: rounds of step_all() on the calling thread —
  /// source pull -> workers -> merge -> sink — until no stage can progress
  /// (the source has nothing more for now), the stream has finished, or
  /// `budget_ns` has elapsed. Creates no thread, never sleeps or waits, does
  /// not allocate. The budget is checked between rounds: one call can exceed
  /// it by one round (one source chunk of up to batch_events events through
  /// every stage). Work left when the budget ends stays queued for the next
  /// call; what the source cannot buffer meanwhile is its own to count.
  PipelineRunReport run_for(std::int64_t budget_ns) noexcept;

  /// After a camera's clock restarted (its times start again below the
  /// last ones, which every estimator rejects as going backwards: counted in
  /// stats().rejected()): empties every worker's estimator as
  /// LifetimeEstimator::reset() does, without allocating. Call it from the
  /// thread that steps the pipeline, between the old clock's events and the
  /// new one's: true when no event is held by the router or queued for or
  /// inside a worker (run_for() returned with the source empty); false, and
  /// nothing reset, otherwise. The pipeline's own counters go on. Not for the
  /// threaded Engine (make a new one). A file written by a WriterSink ends at
  /// the first event of the new clock (a writer refuses a time going back:
  /// no reader would take the file): give the new clock a new sink.
  bool reset_estimators() noexcept;

  Router& router() noexcept { return *router_; }
  TileWorker& worker(int w) noexcept { return *workers_[static_cast<std::size_t>(w)]; }
  int worker_count() const noexcept { return static_cast<int>(workers_.size()); }
  Merger& merger() noexcept { return *merger_; }
  /// Runs the merger on whichever thread has merge work (see merge_role.h).
  StepResult drain_merger() noexcept {
    return merge_role_.drain([this]() noexcept { return merger_->step(); });
  }
  PipelineState& state() noexcept { return *state_; }
  EventSource& source() noexcept { return source_; }

  /// Snapshot of the counters (any thread, any time).
  EngineStats stats() const;

 private:
  EventSource& source_;
  std::unique_ptr<PipelineState> state_;
  std::unique_ptr<Router> router_;
  std::vector<std::unique_ptr<TileWorker>> workers_;
  std::unique_ptr<Merger> merger_;
  MergeRole merge_role_;
  std::vector<AuxStage*> aux_;
};

}  // namespace evlife::engine
