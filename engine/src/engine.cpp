#include "evlife/engine/engine.h"

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#if defined(__linux__)
#include <sys/prctl.h>
#endif

#include <spdlog/spdlog.h>

#include "evlife/engine/monotonic_clock.h"
#include "evlife/engine/realtime_thread.h"
#include "evlife/engine/thread_cpu_clock.h"

namespace evlife::engine {

int RunResult::exit_code() const noexcept {
  switch (status) {
    case RunStatus::completed: return kExitOk;
    case RunStatus::interrupted: return kExitInterrupted;
    case RunStatus::source_error: return kExitInput;
    case RunStatus::sink_error: return kExitOutput;
    case RunStatus::realtime_error: return kExitRealtime;
  }
  return kExitFailure;
}

Engine::Engine(EventSource& source, AugmentedSink* sink, const EngineOptions& options)
    : pipeline_(source, sink, options), options_(options) {}

namespace {
constexpr std::int64_t kIdleWaitUs = 1000;  // re-check stop/done flags at least this often
constexpr std::int64_t kBackstopWaitUs = 100'000;  // the merger backstop is signalled when needed
// A router blocked on a full pool is signalled when half of it is free
// (PipelineState::room_returned); a timeout shorter than draining half a
// pool would wake it early for a few batches at a time.
constexpr std::int64_t kBlockedWaitUs = 20'000;
// Longest stretch of the hosted worker's steps between two pulls: a few
// packet periods' worth of its work at camera rates.
constexpr std::int64_t kHostedBudgetNs = 200'000;

// Polls `wake` for up to spin_ns (work signalled) before sleeping on it.
// Polling yields the core between looks: with more busy threads than cores
// (2 workers + the source thread on 2), a pause-only spin starved the source
// thread (p50 latency 400 us); yielding keeps the vCPU awake for the next
// batch without taking it from anyone.
void park(Semaphore& wake, std::int64_t spin_ns) noexcept {
  if (spin_ns > 0) {
    const std::int64_t until = monotonic_ns() + spin_ns;
    while (wake.availableApprox() <= 0 && monotonic_ns() < until) std::this_thread::yield();
  }
  wake.wait(kIdleWaitUs);
}
}  // namespace

int live_hosted_worker(OverloadPolicy policy, SourceKind kind, int workers) noexcept {
  return policy == OverloadPolicy::drop && kind == SourceKind::live && workers >= 2 ? workers - 1 : -1;
}

RunResult Engine::run() {
  PipelineState& state = pipeline_.state();
  EventSource& source = pipeline_.source();
  std::atomic<bool> merger_done{false};
  Semaphore monitor_wake;

  const int idle_spin_us =
      effective_idle_spin_us(options_, source.kind() == SourceKind::live);
  spdlog::info("engine: {} -> {} workers, tiles {}x{} per polarity, margin {} px, policy {}, "
               "{} batches x {} events per worker, idle spin {} us",
               source.describe(), options_.workers, options_.tiles_x, options_.tiles_y,
               state.layout.margin_px(),
               state.policy == OverloadPolicy::block ? "block" : "drop",
               options_.batches_per_worker, options_.batch_events, idle_spin_us);

  // Real-time settings first (realtime_options.h): every thread waits at the
  // gate until the creating thread has pinned it and set its policy; if
  // anything is refused, the threads leave without touching the pipeline.
  const RealtimeOptions& rt = options_.realtime;
  std::string rt_error;
  if (rt.lock_memory) rt_error = lock_process_memory();
  std::atomic<int> gate{0};  // 0 wait, 1 run, 2 leave
  const auto pass_gate = [&gate]() noexcept {
    int g;
    // Sleeps (futex), not spins: a SCHED_FIFO thread spinning here could keep
    // the creating thread off its CPU.
    while ((g = gate.load(std::memory_order_acquire)) == 0) gate.wait(0, std::memory_order_acquire);
    return g == 1;
  };
  std::vector<std::thread> threads;
  std::vector<std::string> thread_names;
  // Each thread's CPU time at its end, by index in `threads` (read after join).
  std::vector<std::int64_t> thread_cpu(2 + static_cast<std::size_t>(pipeline_.worker_count()) +
                                       pipeline_.aux_stages().size(), 0);
  // Live runs with 2+ workers: the source thread runs the last worker's
  // steps itself between pulls (live_hosted_worker()); worker 0's thread
  // merges its outputs (the source thread never calls the sink, whose
  // speed is not ours to bound).
  const int hosted = live_hosted_worker(state.policy, source.kind(), pipeline_.worker_count());
  TileWorker* const hosted_worker = hosted >= 0 ? &pipeline_.worker(hosted) : nullptr;
  if (hosted_worker != nullptr) hosted_worker->publish_every(TileWorker::kLiveStepEvents);
  Semaphore& merge_helper = state.workers.front()->wake_worker;
  const auto record_cpu = [&thread_cpu](std::size_t index) noexcept { thread_cpu[index] = thread_cpu_ns(); };
  if (!rt_error.empty()) gate.store(2, std::memory_order_release);  // before any thread: no notify needed
  threads.emplace_back([&] {
    if (!pass_gate()) return;
#if defined(__linux__)
    // Paced sleeps (replay packets) must end on time: the default 50 us
    // timer slack would add up to 50 us to every event's latency.
    prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
#endif
    Router& router = pipeline_.router();
    // The hosted worker's queue is worked off after each pull, for at most
    // kHostedBudgetNs before the next pull: the source is never held up
    // longer (a camera's transfers are reaped by pull(); overload shows as
    // counted drops when the hosted worker's pool runs out, as for the
    // others). Each step's outputs are handed to worker 0 to merge.
    const auto run_hosted = [&](std::int64_t until) noexcept {
      while (hosted_worker->step() == StepResult::progressed) {
        wake(merge_helper);
        if (monotonic_ns() >= until) break;
      }
    };
    for (;;) {
      const StepResult r = router.step();
      if (r == StepResult::finished) break;
      if (hosted_worker != nullptr) run_hosted(monotonic_ns() + kHostedBudgetNs);
      if (r == StepResult::blocked) state.wake_router.wait(kBlockedWaitUs);
      else if (r == StepResult::idle) std::this_thread::yield();  // pull() paces itself
    }
    // To its end (the router has finished: its queue is final); its last
    // step wakes the merger backstop, which merges what worker 0 left.
    if (hosted_worker != nullptr) run_hosted(INT64_MAX);
    record_cpu(0);
  });
  thread_names.emplace_back(hosted >= 0 ? "source+worker" + std::to_string(hosted) : "source");
  for (int w = 0; w < pipeline_.worker_count(); ++w) {
    if (w == hosted) continue;
    thread_names.push_back("worker" + std::to_string(w));
    const std::size_t cpu_index = threads.size();
    threads.emplace_back([&, w, cpu_index] {
      if (!pass_gate()) return;
      TileWorker& worker = pipeline_.worker(w);
      WorkerChannel& channel = *state.workers[static_cast<std::size_t>(w)];
      const std::int64_t spin_ns = std::int64_t{idle_spin_us} * 1000;
      // Offline (policy block) throughput counts: a worker with more than
      // half its pool of input waiting leaves the merge to a less loaded one
      // (the busiest worker sets the pace; 2 workers: 1.57x -> 1.62x on the
      // recordings). At half, it merges: the router, blocked until half a
      // pool is free (PipelineState::room_returned), then refills the queues
      // before they run dry; merging only when dry left one worker idle while
      // the other merged half a pool. Live (drop), latency counts: merge at
      // once, else a burst holds merged output and batches back (p99 x5,
      // drops: tried).
      const bool defer_merge_when_busy =
          state.policy == OverloadPolicy::block && pipeline_.worker_count() > 1;
      const std::size_t merge_below = channel.pool.size() / 2 + 1;
      // Live: outputs published (and merged) every few events of a batch.
      if (state.policy == OverloadPolicy::drop) worker.publish_every(TileWorker::kLiveStepEvents);
      for (;;) {
        const StepResult r = worker.step();
        if (r == StepResult::finished) break;
        if (r == StepResult::progressed) {
          if (!defer_merge_when_busy || channel.in.size_approx() < merge_below) pipeline_.drain_merger();
        } else {
          pipeline_.drain_merger();
          park(channel.wake_worker, spin_ns);
        }
      }
      record_cpu(cpu_index);
    });
  }
  thread_names.emplace_back("merger");
  const std::size_t merger_cpu_index = threads.size();
  threads.emplace_back([&, merger_cpu_index] {
    if (!pass_gate()) {
      merger_done.store(true, std::memory_order_release);
      return;
    }
    // Backstop: workers merge as they finish batches; this thread merges
    // what is left when the render tap frees room, for chunks whose events
    // were all dropped, and at the end (where it also finishes the sink).
    // It sleeps until signalled (rarely): taking the role on a timer would
    // let this thread be preempted while holding it, stalling the workers.
    for (;;) {
      if (pipeline_.drain_merger() == StepResult::finished) break;
      state.wake_merger.wait(kBackstopWaitUs);
    }
    record_cpu(merger_cpu_index);
    merger_done.store(true, std::memory_order_release);
    monitor_wake.signal();
  });
  std::atomic<int> aux_running{static_cast<int>(pipeline_.aux_stages().size())};
  for (AuxStage* aux : pipeline_.aux_stages()) {
    thread_names.emplace_back("render");
    const std::size_t cpu_index = threads.size();
    threads.emplace_back([&, aux, cpu_index] {
      if (!pass_gate()) {
        aux_running.fetch_sub(1, std::memory_order_release);
        return;
      }
      for (;;) {
        const StepResult r = aux->step();
        if (r == StepResult::finished) break;
        if (r != StepResult::progressed) aux->wake().wait(kIdleWaitUs);
      }
      record_cpu(cpu_index);
      aux_running.fetch_sub(1, std::memory_order_release);
      monitor_wake.signal();
    });
  }

  std::string applied_cpus;
  for (std::size_t i = 0; i < threads.size() && rt_error.empty(); ++i) {
    const int cpu = rt.cpus.empty() ? -1 : rt.cpus[i % rt.cpus.size()];
    rt_error = pin_thread(threads[i].native_handle(), cpu);
    if (cpu >= 0) applied_cpus += " " + thread_names[i] + ":" + std::to_string(cpu);
    if (rt_error.empty() && thread_names[i] != "render") {
      rt_error = set_fifo_priority(threads[i].native_handle(), rt.rt_priority);
    }
  }
  if (!rt_error.empty()) {
    gate.store(2, std::memory_order_release);
    gate.notify_all();
    for (auto& t : threads) t.join();
    if (rt.lock_memory) unlock_process_memory();  // nothing of this run stays locked
    RunResult refused;
    refused.status = RunStatus::realtime_error;
    refused.message = rt_error;
    refused.stats = pipeline_.stats();
    refused.realtime = "refused";
    return refused;  // the caller reports refused.message (the CLI once, exit 5)
  }
  std::string applied;
  if (!applied_cpus.empty()) applied += "cpus" + applied_cpus;
  if (rt.rt_priority > 0)
    applied += (applied.empty() ? "" : "; ") + std::string("SCHED_FIFO ") + std::to_string(rt.rt_priority) +
               " (source, workers, merger)";
  if (rt.lock_memory) {
    const long long locked = locked_memory_bytes();
    char mib[64];
    std::snprintf(mib, sizeof mib, "%.1f MiB", static_cast<double>(locked) / (1024.0 * 1024.0));
    applied += (applied.empty() ? "" : "; ") + std::string("memory locked (mlockall current+future, ") +
               (locked >= 0 ? mib : "size unknown") + " locked at start)";
  }
  if (applied.empty()) applied = "none (default scheduling, threads not pinned, memory not locked)";
  gate.store(1, std::memory_order_release);
  gate.notify_all();

  // Monitor: stop requests, progress lines; never on the data path.
  bool stop_forwarded = false;
  std::uint64_t failed_transfers_seen = 0;
  // Rounded up: a period under 1 ns is 1 ns (a line per wake-up), not 0 (none).
  const auto period_ns = static_cast<std::int64_t>(std::ceil(options_.stats_period_s * 1e9));
  const std::int64_t started_ns = monotonic_ns();
  std::int64_t next_report_ns = started_ns + period_ns;
  const auto say_notices = [this, &source] {
    for (std::string notice = source.take_notice(); !notice.empty(); notice = source.take_notice())
      spdlog::warn("replay: {}", notice);
    for (AuxStage* aux : pipeline_.aux_stages())
      for (std::string notice = aux->take_notice(); !notice.empty(); notice = aux->take_notice())
        spdlog::warn("render: {}", notice);
  };
  while (!merger_done.load(std::memory_order_acquire) ||
         aux_running.load(std::memory_order_acquire) > 0) {
    monitor_wake.wait(10'000);
    if (!stop_forwarded && stop_.load(std::memory_order_relaxed)) {
      spdlog::info("engine: stop requested, finishing the queued work");
      source.request_stop();
      for (AuxStage* aux : pipeline_.aux_stages()) aux->request_stop();
      stop_forwarded = true;
    }
    say_notices();
    if (const std::uint64_t failed = source.failed_transfers(); failed > failed_transfers_seen) {
      spdlog::warn("engine: {} device transfer(s) failed; their events are lost ({} in all)",
                   failed - failed_transfers_seen, failed);
      failed_transfers_seen = failed;
    }
    if (!stop_forwarded && pipeline_.merger().sink_failed()) {
      spdlog::error("engine: the output failed; stopping the source");
      source.request_stop();
      stop_forwarded = true;
    }
    if (period_ns > 0 && monotonic_ns() >= next_report_ns) {
      std::string done;  // how far through a file, and when it will end at this pace
      if (const double f = source.fraction_read(); f > 0.0) {
        const double elapsed_s = static_cast<double>(monotonic_ns() - started_ns) * 1e-9;
        done = fmt::format("{:.1f} % of the input, ETA {:.0f} s | ", 100.0 * f, elapsed_s * (1.0 - f) / f);
      }
      spdlog::info("engine: {}{}", done, pipeline_.stats().progress_line());
      next_report_ns += period_ns;
    }
  }
  for (auto& t : threads) t.join();
  say_notices();  // those made after the loop's last look

  RunResult result;
  result.realtime = applied;
  for (std::size_t i = 0; i < threads.size(); ++i)
    result.thread_cpu_s.emplace_back(thread_names[i], static_cast<double>(thread_cpu[i]) * 1e-9);
  result.stats = pipeline_.stats();
  // A failed output first: what was written is then less than what was
  // processed, whatever else happened (an input fault too is named).
  if (pipeline_.merger().sink_failed()) {
    result.status = RunStatus::sink_error;
    result.message = pipeline_.merger().sink_error();
    if (pipeline_.router().source_failed())
      result.message += " (the input had failed as well: " + source.error_message() + ")";
  } else if (pipeline_.router().source_failed()) {
    result.status = RunStatus::source_error;
    result.message = source.error_message();
  } else if (stop_.load(std::memory_order_relaxed)) {
    result.status = RunStatus::interrupted;
  }
  return result;
}

}  // namespace evlife::engine

// g++ says __SANITIZE_THREAD__, clang __has_feature(thread_sanitizer).
#if defined(__SANITIZE_THREAD__)
#define EVLIFE_TSAN_BUILD 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define EVLIFE_TSAN_BUILD 1
#endif
#endif

#if defined(EVLIFE_TSAN_BUILD)
// ThreadSanitizer cannot see synchronization made by std::atomic_thread_fence
// (GCC warns: -Wtsan), and moodycamel::ConcurrentQueue hands block slots
// between producer and consumer with relaxed loads plus fences, so TSan
// reports a false race when a slot is reused (its own header says "TSAN can
// false report races in lock-free code" but only silences it under clang).
// Suppress races whose stacks are inside the queue; races on the batches
// themselves (our code: router memcpy vs worker reads) still report.
// Also: OpenCV's imwrite goes through GDAL, whose CPL mutexes are taken in
// varying order within the one render thread; TSan reports a potential
// lock-order inversion inside libgdal (`evlife run --frames`), not ours.
extern "C" const char* __tsan_default_suppressions() {
  return "race:moodycamel::ConcurrentQueue\n"
         "deadlock:libgdal.so\n";
}
#endif
