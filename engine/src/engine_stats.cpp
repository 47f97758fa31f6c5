#include "evlife/engine/engine_stats.h"

#include <fmt/format.h>

namespace evlife::engine {

std::string EngineStats::progress_line() const {
  std::string hwm;
  for (const auto& w : workers)
    hwm += fmt::format("{}{}/{}", hwm.empty() ? "" : " ", w.in_flight_hwm, w.pool_batches);
  return fmt::format(
      "in {} out {} dropped {} | queues hwm [{}] | latency p50 {:.0f} us p99 {:.0f} us max {:.0f} us",
      events_in, events_out, events_dropped, hwm, latency_p50_us, latency_p99_us,
      latency_max_us);
}

std::string EngineStats::summary() const {
  std::string s;
  s += fmt::format("source : accepted {} events in {} chunks, lost in source {}{}, "
                   "waited for room {:.3f} s\n",
                   events_in, chunks, source_lost,
                   source_failed_transfers == 0
                       ? std::string()
                       : fmt::format(" (and {} failed device transfers: their events are lost, not all counted)",
                                     source_failed_transfers),
                   source_blocked_s);
  s += fmt::format("router : dropped {} (of which whole chunks, no merge slot: {}), "
                   "merge-order hwm {}\n",
                   events_dropped, dropped_no_order, order_in_flight_hwm);
  for (std::size_t w = 0; w < workers.size(); ++w) {
    const WorkerStats& ws = workers[w];
    s += fmt::format("worker {}: fed {} (owned {}, margin {}), {} batches, busy {:.3f} s "
                     "(CPU {:.3f} s, {:.0f} ns/event), dropped {}, queue hwm {}/{}{}\n",
                     w, ws.events_fed, ws.events_owned, ws.events_fed - ws.events_owned,
                     ws.batches, ws.busy_s, ws.busy_cpu_s,
                     ws.events_fed > 0 ? ws.busy_cpu_s * 1e9 / static_cast<double>(ws.events_fed) : 0.0,
                     ws.dropped, ws.in_flight_hwm, ws.pool_batches,
                     ws.rejected > 0 ? fmt::format(", rejected {} (labelled noise unexamined)", ws.rejected) : "");
  }
  s += fmt::format("merger : out {} (sink failed on {}), latency arrival->output "
                   "p50 {:.1f} us p99 {:.1f} us max {:.1f} us over {} events\n",
                   events_out, sink_failed, latency_p50_us, latency_p99_us, latency_max_us,
                   latency_count);
  s += fmt::format("         age of each chunk's oldest event at output (latency + wait for its "
                   "packet) p50 {:.1f} us p99 {:.1f} us max {:.1f} us\n",
                   age_p50_us, age_p99_us, age_max_us);
  if (latency_count > 0) {
    std::string started, estimated;
    for (const auto& w : workers) {
      started += fmt::format("{}{:.1f}/{:.1f}", started.empty() ? "" : " ", w.started_p50_us, w.started_p99_us);
      estimated += fmt::format("{}{:.1f}/{:.1f}", estimated.empty() ? "" : " ", w.estimated_p50_us, w.estimated_p99_us);
    }
    s += fmt::format("         latency by stage, p50/p99 us from arrival: pulled by the source {:.1f}/{:.1f}"
                     " (sources with arrival times), worker started [{}], estimated [{}], output "
                     "{:.1f}/{:.1f}\n",
                     pulled_p50_us, pulled_p99_us, started, estimated, latency_p50_us, latency_p99_us);
  }
  if (render_offered > 0)
    s += fmt::format("render : offered {} events, skipped {} (render thread behind)\n",
                     render_offered, render_dropped);
  s += fmt::format("balance: in {} = out {} + dropped {} : {}", events_in, events_out,
                   events_dropped, events_in == events_out + events_dropped ? "ok" : "MISMATCH");
  if (source_lost > 0 || source_failed_transfers > 0)  // before "in": the balance cannot show them
    s += fmt::format("; lost before the engine: {} events{}", source_lost,
                     source_failed_transfers == 0 ? std::string()
                                                  : fmt::format(" and {} failed device transfers", source_failed_transfers));
  // "out" counts what reached the sink; a failed sink kept none of it after the failure.
  if (sink_failed > 0)
    s += fmt::format(", but {} of the out were not written (the output failed)", sink_failed);
  return s;
}

}  // namespace evlife::engine
