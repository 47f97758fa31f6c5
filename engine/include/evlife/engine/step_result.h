#pragma once

namespace evlife::engine {

/// What one step() of a stage did; the thread loop sleeps on anything but
/// `progressed`, a test's inline loop just moves on to the next stage.
enum class StepResult {
  progressed,  ///< did some work; call again
  idle,        ///< nothing to do right now
  blocked,     ///< waiting for room downstream (policy block)
  finished,    ///< will never have work again
};

}  // namespace evlife::engine
