// Who runs the merger. Handing every finished batch to a merger thread costs
// a thread wake-up per batch (tens of microseconds on a VM whose idle vCPU
// halts); instead, the worker that has just finished a batch merges it
// itself, and the merger thread is only a backstop (render tap room, end of
// stream, chunks whose events were all dropped).
//
// Non-blocking: a thread that finds the role taken does not wait; it leaves
// a request, and the holder keeps merging until no request came in while it
// held the role, so no finished batch is left unmerged. The merger is only
// ever run by one thread at a time, and every hand-over of the role is a
// release/acquire pair, so Merger's single-owner state stays race-free.
#pragma once

#include <atomic>
#include <cstdint>

#include "evlife/engine/step_result.h"

namespace evlife::engine {

class MergeRole {
 public:
  /// Runs `step` (the merger's) until it stops progressing, if no other
  /// thread holds the role; else returns idle at once and the holder picks
  /// the work up. Returns the last result of `step` this thread saw.
  template <class Step>
  StepResult drain(Step&& step) noexcept {
    // seq_cst throughout: the request (RMW) before the try (RMW) here, and
    // the release before the re-check (load) in the holder, must not both be
    // missed (store-load ordering). The release is an RMW, not a store: a
    // seq_cst store then load is ordered on the hardware (aarch64 stlr, ldar)
    // but not by every emulator of it (qemu-user on x86-64 let one in four
    // runs of MergeRole's test leave a request behind); an RMW is a full
    // barrier everywhere, and this runs once per drain, not per event.
    requests_.fetch_add(1);
    StepResult last = StepResult::idle;
    for (;;) {
      if (held_.exchange(true)) return StepResult::idle;  // the holder will see our request
      std::uint64_t seen = 0;
      do {
        seen = requests_.load();
        while ((last = step()) == StepResult::progressed) {
        }
      } while (requests_.load() != seen);
      held_.exchange(false);
      if (requests_.load() == seen) return last;
      // A request arrived between our last look and the release: take the
      // role again (or leave it to whoever took it meanwhile).
    }
  }

 private:
  std::atomic<std::uint64_t> requests_{0};
  std::atomic<bool> held_{false};
};

}  // namespace evlife::engine
