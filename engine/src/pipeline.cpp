#include "evlife/engine/pipeline.h"

namespace evlife::engine {

namespace {
OverloadPolicy policy_for(const EngineOptions& options, const EventSource& source) {
  if (!options.auto_policy) return options.policy;
  return source.kind() == SourceKind::live ? OverloadPolicy::drop : OverloadPolicy::block;
}
}  // namespace

Pipeline::Pipeline(EventSource& source, AugmentedSink* sink, const EngineOptions& options)
    : source_(source),
      state_(std::make_unique<PipelineState>(options, source.sensor_size(),
                                             policy_for(options, source))) {
  router_ = std::make_unique<Router>(*state_, source);
  for (int w = 0; w < options.workers; ++w)
    workers_.push_back(std::make_unique<TileWorker>(*state_, w));
  merger_ = std::make_unique<Merger>(*state_, sink);
}

bool Pipeline::step_all() noexcept {
  router_->step();
  for (auto& w : workers_) w->step();
  bool done = drain_merger() == StepResult::finished;
  for (AuxStage* a : aux_) done = (a->step() == StepResult::finished) && done;
  return done;
}

bool Pipeline::reset_estimators() noexcept {
  if (router_->holds_a_chunk()) return false;
  for (const auto& w : workers_)
    if (!w->idle()) return false;
  for (auto& w : workers_) w->reset_estimator();
  return true;
}

EngineStats Pipeline::stats() const {
  const PipelineState& s = *state_;
  EngineStats st;
  st.source_lost = source_.lost_events();
  st.source_failed_transfers = source_.failed_transfers();
  st.events_in = s.router_counters.events_in.get();
  st.events_dropped = s.router_counters.dropped.get();
  st.dropped_no_order = s.router_counters.dropped_no_order.get();
  st.chunks = s.router_counters.chunks.get();
  st.order_in_flight_hwm = s.router_counters.order_in_flight_hwm.get();
  st.source_blocked_s = static_cast<double>(s.router_counters.blocked_ns.get()) * 1e-9;
  st.events_out = s.merger_counters.events_out.get();
  if (s.merger_counters.event_t_us.seen()) {
    st.has_time_range = true;
    st.first_t_us = s.merger_counters.event_t_us.first();
    st.last_t_us = s.merger_counters.event_t_us.last();
  }
  if (s.render_tap) {
    st.render_offered = s.render_tap->offered_events.get();
    st.render_dropped = s.render_tap->dropped_events.get();
  }
  st.sink_failed = s.merger_counters.sink_failed_events.get();
  const auto us = [](const LatencyHistogram& hist, double q) {
    return static_cast<double>(hist.percentile_ns(q)) * 1e-3;
  };
  const auto max_us = [](const LatencyHistogram& hist) { return static_cast<double>(hist.max_ns()) * 1e-3; };
  const LatencyHistogram& h = s.merger_counters.latency_ns;
  st.latency_count = h.count();
  st.latency_p50_us = us(h, 0.50);
  st.latency_p99_us = us(h, 0.99);
  st.latency_max_us = max_us(h);
  st.latency_over_1ms = h.count_above(1'000'000);
  const LatencyHistogram& age = s.merger_counters.age_ns;
  st.age_p50_us = us(age, 0.50);
  st.age_p99_us = us(age, 0.99);
  st.age_max_us = max_us(age);
  st.pulled_p50_us = us(s.router_counters.pulled_ns, 0.50);
  st.pulled_p99_us = us(s.router_counters.pulled_ns, 0.99);
  for (std::size_t w = 0; w < s.workers.size(); ++w) {
    const WorkerChannel& ch = *s.workers[w];
    WorkerStats ws;
    ws.batches = ch.counters.batches.get();
    ws.events_fed = ch.counters.events_fed.get();
    ws.events_owned = ch.counters.events_owned.get();
    ws.busy_s = static_cast<double>(ch.counters.busy_ns.get()) * 1e-9;
    ws.busy_cpu_s = static_cast<double>(ch.counters.busy_cpu_ns.get()) * 1e-9;
    ws.dropped = s.router_counters.dropped_for_worker[w].get();
    ws.rejected = ch.counters.rejected.get();
    ws.in_flight_hwm = s.router_counters.in_flight_hwm[w].get();
    ws.pool_batches = ch.pool.size();
    ws.started_p50_us = us(ch.counters.started_ns, 0.50);
    ws.started_p99_us = us(ch.counters.started_ns, 0.99);
    ws.estimated_p50_us = us(ch.counters.estimated_ns, 0.50);
    ws.estimated_p99_us = us(ch.counters.estimated_ns, 0.99);
    st.workers.push_back(ws);
  }
  return st;
}

}  // namespace evlife::engine
