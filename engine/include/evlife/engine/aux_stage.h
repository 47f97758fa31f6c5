// A stage beyond the data path (the render thread): the Engine runs its
// step() on a thread of its own, Pipeline::step_all() calls it inline.
#pragma once

#include <concurrentqueue.h>  // before the semaphore: it defines the macros it uses
#include <lightweightsemaphore.h>

#include <string>

#include "evlife/engine/step_result.h"

namespace evlife::engine {

class AuxStage {
 public:
  virtual ~AuxStage() = default;
  /// Never throws; `finished` once it will never have work again.
  virtual StepResult step() noexcept = 0;
  /// Signalled when the stage may have work (its thread sleeps on it).
  virtual moodycamel::LightweightSemaphore& wake() noexcept = 0;
  /// The run is stopping (Ctrl-C): skip what only the user would have
  /// waited for (drawing); any thread.
  virtual void request_stop() noexcept {}
  /// The next warning for the user, oldest first, taken by the monitor
  /// thread (never on the stage's own path) until it is empty: none (yet).
  virtual std::string take_notice() { return {}; }

 protected:
  AuxStage() = default;
  AuxStage(const AuxStage&) = default;
  AuxStage& operator=(const AuxStage&) = default;
};

}  // namespace evlife::engine
