// A snapshot of the engine's counters, for the periodic progress line, the
// final summary and tests. Invariant once a run has ended:
//   events_in == events_out + events_dropped.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace evlife::engine {

struct WorkerStats {
  std::uint64_t batches = 0;
  std::uint64_t events_fed = 0;    ///< owned + margin
  std::uint64_t events_owned = 0;
  std::uint64_t dropped = 0;       ///< owned events the router dropped for it
  /// Owned events its estimator labelled noise unexamined: outside the
  /// sensor, bad polarity, time beyond +-2^62 us, or earlier than the last
  /// event of its polarity it was fed (a camera's clock restarted). Output
  /// (as noise), never dropped; the margin events it was fed are not counted.
  std::uint64_t rejected = 0;
  std::uint64_t in_flight_hwm = 0; ///< batches queued or held, high-water mark
  std::uint64_t pool_batches = 0;  ///< its pool size (the bound of the above)
  double busy_s = 0.0;
  double busy_cpu_s = 0.0;  ///< CPU time of busy_s: per-event cost even on a loaded machine
  /// Latency's worker stages (from the chunk's arrival, per event): batch
  /// started, event estimated.
  double started_p50_us = 0.0;
  double started_p99_us = 0.0;
  double estimated_p50_us = 0.0;
  double estimated_p99_us = 0.0;
};

struct EngineStats {
  std::uint64_t source_lost = 0;   ///< lost inside the source (device overflow)
  std::uint64_t source_failed_transfers = 0;  ///< device reads that failed (their events lost, maybe uncounted)
  std::uint64_t events_in = 0;     ///< accepted from the source
  std::uint64_t events_out = 0;    ///< handed to the sink
  /// Recording time of the first and last event handed to the sink (us);
  /// meaningful when has_time_range (some event was handed out).
  bool has_time_range = false;
  std::int64_t first_t_us = 0;
  std::int64_t last_t_us = 0;
  std::uint64_t events_dropped = 0;
  std::uint64_t dropped_no_order = 0;
  std::uint64_t sink_failed = 0;
  std::uint64_t chunks = 0;
  std::uint64_t render_offered = 0;  ///< merged events offered to the render branch
  std::uint64_t render_dropped = 0;  ///< of which skipped: render behind (policy drop)
  std::uint64_t order_in_flight_hwm = 0;
  double source_blocked_s = 0.0;
  std::uint64_t latency_count = 0;
  double latency_p50_us = 0.0;
  double latency_p99_us = 0.0;
  double latency_max_us = 0.0;
  /// Events output more than 1 ms after their arrival: a stall of the
  /// engine's threads (another task holding a core for a scheduler tick)
  /// rather than its processing; p99 goes to ms once they pass 1 %.
  std::uint64_t latency_over_1ms = 0;
  /// Age at output of each chunk's oldest event (latency + its wait for the
  /// packet); equals the latency when the source does not know event times.
  double age_p50_us = 0.0;
  double age_p99_us = 0.0;
  double age_max_us = 0.0;
  /// Latency's first stage, sources that state arrival times: arrival ->
  /// pulled by the source thread (a late source thread shows here).
  double pulled_p50_us = 0.0;
  double pulled_p99_us = 0.0;
  std::vector<WorkerStats> workers;

  /// The workers' rejected events (each counted once, by its owner).
  std::uint64_t rejected() const noexcept {
    std::uint64_t n = 0;
    for (const WorkerStats& w : workers) n += w.rejected;
    return n;
  }

  /// One line: in/out/dropped, queue high-water marks, latency percentiles.
  std::string progress_line() const;
  /// Multi-line summary, one line per stage.
  std::string summary() const;
};

}  // namespace evlife::engine
