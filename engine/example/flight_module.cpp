// The pipeline inside someone else's scheduler, in the style of a PX4 module:
// the host owns every thread; the module's Run() is called periodically (here
// every 1 ms of a simulated work queue), takes the camera packets that
// arrived since the last call, runs the evlife stages for at most a time
// budget, and reads the active-event map (which pixels hold an edge now).
// Built as `evlife_flight_module_example`; ctest runs it (README: "The
// pipeline inside your scheduler").
//
// It checks itself and exits non-zero when: any event is lost or left
// unprocessed, the output differs from the bare LifetimeEstimator run on the
// same events (bit for bit: the module must not change results), no edge is
// ever active, or a Run() created a thread.
#include <dirent.h>

#include <cstdio>
#include <cstring>
#include <span>
#include <vector>

#include "evlife/algo/lifetime_estimator.h"
#include "evlife/engine/augmented_sink.h"
#include "evlife/engine/packet_source.h"
#include "evlife/engine/pipeline.h"
#include "evlife/io/synthetic_scene.h"
#include "evlife/algo/active_event_map.h"

namespace {

// Threads of this process (/proc/self/task): Run() must not add any.
int thread_count() {
  int n = 0;
  if (DIR* d = opendir("/proc/self/task")) {
    while (const dirent* e = readdir(d)) n += e->d_name[0] != '.';
    closedir(d);
  }
  return n;
}

// Feeds the merged output into the active-event map (called inside run_for).
class ActiveMapSink final : public evlife::engine::AugmentedSink {
 public:
  explicit ActiveMapSink(evlife::SensorSize sensor) : map_(sensor) {}
  void write(std::span<const evlife::AugmentedEvent> events) override {
    map_.feed(events);
    out_.insert(out_.end(), events.begin(), events.end());  // kept only for the self-check
  }
  const evlife::ActiveEventMap& map() const { return map_; }
  const std::vector<evlife::AugmentedEvent>& out() const { return out_; }

 private:
  evlife::ActiveEventMap map_;
  std::vector<evlife::AugmentedEvent> out_;
};

// The module: everything allocated in the constructor (Init), then Run().
class LifetimeModule {
 public:
  LifetimeModule(evlife::SensorSize sensor, const evlife::engine::EngineOptions& options)
      : source_(sensor, kBufferEvents), sink_(sensor), pipeline_(source_, &sink_, options) {}

  // The camera driver's callback (same thread as Run(), between calls).
  void on_camera_packet(std::span<const evlife::Event> packet) { source_.push(packet); }
  void on_camera_closed() { source_.close(); }

  // One step of the work queue: process what arrived, within the budget.
  evlife::engine::PipelineRunReport Run(std::int64_t now_us) {
    const evlife::engine::PipelineRunReport r = pipeline_.run_for(kBudgetNs);
    active_pixels_ = sink_.map().count_active(now_us);
    return r;
  }

  std::size_t active_pixels() const { return active_pixels_; }
  const ActiveMapSink& sink() const { return sink_; }
  evlife::engine::EngineStats stats() const { return pipeline_.stats(); }
  std::uint64_t lost() const { return source_.lost_events(); }

  static constexpr std::int64_t kBudgetNs = 400'000;  // 0.4 ms of a 1 ms period
  static constexpr std::size_t kBufferEvents = 1 << 16;

 private:
  evlife::engine::PacketSource source_;
  ActiveMapSink sink_;
  evlife::engine::Pipeline pipeline_;
  std::size_t active_pixels_ = 0;
};

}  // namespace

int main() {
  // The camera: a synthetic DAVIS240-sized scene (a rotating bar), 0.5 s, in 1 ms packets.
  const evlife::SensorSize sensor{240, 180};
  const evlife::io::SyntheticScene scene =
      evlife::io::generate_scene(evlife::io::rotating_bar_scene(sensor, 500'000, 7));
  const std::vector<evlife::Event>& events = scene.events;

  evlife::engine::EngineOptions options;
  options.lifetime.sensor = sensor;
  options.workers = 2;   // stages, not threads: run_for() runs them all here (one per polarity)
  options.batch_events = 256;  // a round of run_for() moves one chunk: smaller = finer budget
  options.stats_period_s = 0.0;
  LifetimeModule module(sensor, options);

  const int threads_before = thread_count();
  std::size_t next = 0;
  std::size_t max_active = 0;
  int runs = 0, over_budget = 0;
  std::int64_t first_ns = 0, worst_ns = 0;  // the first call touches the state's pages first
  for (std::int64_t now_us = events.front().t_us + 1000;; now_us += 1000) {
    std::size_t end = next;
    while (end < events.size() && events[end].t_us < now_us) ++end;
    module.on_camera_packet(std::span<const evlife::Event>(events.data() + next, end - next));
    next = end;
    if (next == events.size()) module.on_camera_closed();
    const evlife::engine::PipelineRunReport r = module.Run(now_us);
    ++runs;
    over_budget += r.budget_exhausted ? 1 : 0;
    if (runs == 1) first_ns = r.elapsed_ns;
    else worst_ns = std::max(worst_ns, r.elapsed_ns);
    max_active = std::max(max_active, module.active_pixels());
    if (r.finished) break;
    if (runs > 10'000'000) break;  // never: the stream is finite
  }
  const int threads_after = thread_count();

  // Self-check against the bare estimator (no pipeline, no module).
  evlife::LifetimeEstimator bare(options.lifetime);
  std::vector<evlife::AugmentedEvent> expect(events.size());
  bare.process(events, expect);
  const auto& got = module.sink().out();
  const bool same = got.size() == expect.size() &&
                    std::memcmp(got.data(), expect.data(), got.size() * sizeof(expect[0])) == 0;
  const evlife::engine::EngineStats st = module.stats();

  std::printf("flight module: %zu events in %d Run() calls (1 ms period, %.1f ms budget), "
              "%d stopped at the budget, first call %.2f ms, longest other %.2f ms\n",
              events.size(), runs, static_cast<double>(LifetimeModule::kBudgetNs) * 1e-6, over_budget,
              static_cast<double>(first_ns) * 1e-6, static_cast<double>(worst_ns) * 1e-6);
  std::printf("  out %llu, dropped %llu, lost at the source %llu; output %s the bare estimator's; "
              "up to %zu active pixels; threads %d before, %d after\n",
              static_cast<unsigned long long>(st.events_out),
              static_cast<unsigned long long>(st.events_dropped),
              static_cast<unsigned long long>(module.lost()), same ? "equals" : "DIFFERS FROM",
              max_active, threads_before, threads_after);
  const bool ok = same && st.events_out == events.size() && st.events_dropped == 0 && module.lost() == 0 &&
                  max_active > 0 && threads_after == threads_before;
  return ok ? 0 : 1;
}
