// A stage beyond the data path (the render thread): the Engine runs its
// step() on a thread of its own, Pipeline::step_all() calls it inline.
#pragma once

#include <concurrentqueue.h>  // before the semaphore: it defines the macros it uses
#include <lightweightsemaphore.h>

#include "evlife/engine/step_result.h"

namespace evlife::engine {

class AuxStage {
 public:
  virtual ~AuxStage() = default;
  /// Never throws; `finished` once it will never have work again.
  virtual StepResult step() noexcept = 0;
  /// Signalled when the stage may have work (its thread sleeps on it).
  virtual moodycamel::LightweightSemaphore& wake() noexcept = 0;

 protected:
  AuxStage() = default;
  AuxStage(const AuxStage&) = default;
  AuxStage& operator=(const AuxStage&) = default;
};

}  // namespace evlife::engine
