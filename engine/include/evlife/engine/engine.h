// The real-time engine: the Pipeline's stages on their own threads — one
// source/router thread, `workers` estimator threads (live runs with 2+: one
// fewer, the source thread runs the last worker; live_hosted_worker()), one
// merger/output backstop thread — and the calling thread as monitor
// (progress line, stop requests).
// run() returns when the stream has ended or a stop was requested, after
// everything accepted has been processed and handed to the sink and every
// thread has been joined.
#pragma once

#include <atomic>
#include <string>
#include <utility>
#include <vector>

#include "evlife/engine/augmented_sink.h"
#include "evlife/engine/engine_options.h"
#include "evlife/engine/engine_stats.h"
#include "evlife/engine/event_source.h"
#include "evlife/engine/exit_code.h"
#include "evlife/engine/pipeline.h"

namespace evlife::engine {

enum class RunStatus {
  completed,     ///< the source reached its end
  interrupted,   ///< request_stop() (SIGINT/SIGTERM); all accepted work done
  source_error,  ///< the source failed (corrupt file, vanished device)
  sink_error,    ///< the output failed (disk full...)
  realtime_error,  ///< a real-time setting was refused; nothing was processed
};

struct RunResult {
  RunStatus status = RunStatus::completed;
  std::string message;  ///< the source's or sink's error, naming file/device
  EngineStats stats;
  /// What options.realtime applied, for the summary ("none" when off), e.g.
  /// "cpus source:0 worker0:1 worker1:0 merger:1; SCHED_FIFO 50 (source, workers, merger); memory locked (41.2 MiB)".
  std::string realtime;
  /// CPU seconds each engine thread used over the whole run, by thread name
  /// ("source", "worker0", ..., "merger", "render"; live runs:
  /// "source+workerN" for the source thread running worker N): where the CPU goes.
  std::vector<std::pair<std::string, double>> thread_cpu_s;
  /// The exit code of `evlife run` for this result (evlife/engine/exit_code.h):
  /// 0 completed, 3 source error, 4 sink error, 5 real-time setting refused,
  /// 130 interrupted (128 + SIGINT).
  int exit_code() const noexcept;
};

/// The worker whose steps the source thread runs itself (-1: none). Live
/// runs (policy drop, live source) with 2+ workers, where latency counts:
/// the last worker, so its batches need no hand-off to another thread and,
/// with idle polling on, the engine keeps no more polling threads than
/// workers (2 workers on 2 cores: source+worker1 and worker0). The source
/// thread works it off for at most 200 us between pulls and never merges
/// (worker 0 merges its outputs): a camera's transfers and the drop policy
/// do not wait on the estimator or the sink. One worker, and offline runs,
/// keep a thread per worker (the 1-worker merge would land on the source).
/// Offline, the source stays free to refill every queue (throughput).
int live_hosted_worker(OverloadPolicy policy, SourceKind kind, int workers) noexcept;

class Engine {
 public:
  /// `sink` may be null (output discarded, counted). Throws
  /// std::invalid_argument on bad options (naming the field).
  Engine(EventSource& source, AugmentedSink* sink, const EngineOptions& options);

  Engine(const Engine&) = delete;
  Engine& operator=(const Engine&) = delete;

  /// Runs to the end of the stream (or a stop request). Call once.
  RunResult run();

  /// Asks the run to end: the source stops, everything it already handed
  /// over is processed and written. Async-signal-safe (one atomic store).
  void request_stop() noexcept { stop_.store(true, std::memory_order_relaxed); }

  EngineStats stats() const { return pipeline_.stats(); }
  Pipeline& pipeline() noexcept { return pipeline_; }

 private:
  Pipeline pipeline_;
  EngineOptions options_;
  std::atomic<bool> stop_{false};
  static_assert(std::atomic<bool>::is_always_lock_free);
};

}  // namespace evlife::engine
