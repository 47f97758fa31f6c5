#include "evlife/engine/monotonic_clock.h"
#include "evlife/engine/pipeline.h"

namespace evlife::engine {

PipelineRunReport Pipeline::run_for(std::int64_t budget_ns) noexcept {
  const std::int64_t start_ns = monotonic_ns();
  const std::uint64_t out_before = state_->merger_counters.events_out.get();
  PipelineRunReport report;
  for (;;) {
    const std::uint64_t out_round = state_->merger_counters.events_out.get();
    bool progressed = router_->step() == StepResult::progressed;
    for (auto& w : workers_) progressed = (w->step() == StepResult::progressed) || progressed;
    bool done = drain_merger() == StepResult::finished;
    progressed = progressed || state_->merger_counters.events_out.get() != out_round;
    for (AuxStage* a : aux_) {
      const StepResult r = a->step();
      done = (r == StepResult::finished) && done;
      progressed = progressed || r == StepResult::progressed;
    }
    ++report.rounds;
    if (done) {
      report.finished = true;
      break;
    }
    if (!progressed) break;  // nothing more until the source has more
    if (monotonic_ns() - start_ns >= budget_ns) {
      report.budget_exhausted = true;
      break;
    }
  }
  report.elapsed_ns = monotonic_ns() - start_ns;
  report.events_out = state_->merger_counters.events_out.get() - out_before;
  return report;
}

}  // namespace evlife::engine
