// Where the merged, augmented stream goes: a file writer, a callback of an
// embedding application, or nowhere. Called by one thread at a time, never
// concurrently — whichever holds the merge role (merge_role.h: usually the
// worker that completed the chunk, else the merger backstop), so not always
// the same thread — with events in input order; may throw (a file boundary: disk full) — the engine
// then records the error, keeps draining so no thread blocks, and the run
// ends with a non-zero status.
#pragma once

#include <functional>
#include <span>
#include <utility>

#include "evlife/algo/event.h"

namespace evlife::engine {

class AugmentedSink {
 public:
  virtual ~AugmentedSink() = default;
  virtual void write(std::span<const AugmentedEvent> events) = 0;
  /// Called once at the end of the run, after the last write.
  virtual void finish() {}

 protected:
  AugmentedSink() = default;
  AugmentedSink(const AugmentedSink&) = default;
  AugmentedSink& operator=(const AugmentedSink&) = default;
};

/// Hands each merged span to a function (embedding, tests).
class CallbackSink final : public AugmentedSink {
 public:
  using Callback = std::function<void(std::span<const AugmentedEvent>)>;
  explicit CallbackSink(Callback callback) : callback_(std::move(callback)) {}
  void write(std::span<const AugmentedEvent> events) override { callback_(events); }

 private:
  Callback callback_;
};

}  // namespace evlife::engine
