// Options of the engine: thread roles, tiling, queue sizes and overload
// policy. A plain struct with defaults; validate_engine_options() names the
// offending field. Fixed at start: nothing here changes during a run.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "evlife/algo/lifetime_options.h"
#include "evlife/algo/option_info.h"
#include "evlife/engine/realtime_options.h"

namespace evlife::engine {

/// What the router does when a worker's batch pool is exhausted (the worker,
/// the merger or the sink is slower than the source).
enum class OverloadPolicy {
  block,  ///< wait for room: nothing lost, the source is slowed (files)
  drop,   ///< drop the batch's events for that worker, counted (live cameras)
};

struct EngineOptions {
  /// Estimator options; `lifetime.sensor` is overwritten by the source's size.
  LifetimeOptions lifetime;

  /// Worker threads, each owning a set of tiles. 1..32.
  int workers = 2;

  /// Each polarity's sensor is cut into tiles_x by tiles_y tiles; the
  /// 2 * tiles_x * tiles_y tiles are dealt to the workers round robin
  /// (polarity-major, so with 1x1 tiles and 2 workers: ON -> 0, OFF -> 1).
  int tiles_x = 1;
  int tiles_y = 1;

  /// Pixels around a worker's tiles whose events it is also fed (outputs
  /// discarded) so that windows reaching across a tile border see the same
  /// past as the single-threaded estimator. -1: automatic (4 * window_size;
  /// see the README for the measured effect). Ignored with 1x1 tiles.
  int margin_px = -1;

  /// Events per batch (the unit moved through the queues). 16..65536.
  std::size_t batch_events = 1024;

  /// Batches per worker in flight (its pool and queue capacity). 2..1024.
  std::size_t batches_per_worker = 64;

  /// When workers lag. auto_policy: block for offline sources, drop for live ones.
  bool auto_policy = true;
  OverloadPolicy policy = OverloadPolicy::block;

  /// Batches of the merged stream buffered for the render thread; 0 = no
  /// render branch. Full: the merger waits (block) or skips them, counted (drop).
  std::size_t render_batches = 0;

  /// How long an idle worker polls its queue (yielding the core between
  /// looks) before it sleeps in the kernel, microseconds, 0..100000; -1:
  /// automatic (kAutoIdleSpinUs for live sources, where latency counts; 0
  /// for offline ones, and under realtime.rt_priority, whose polling threads
  /// trip the kernel's RT throttling). 0: sleep at once, no CPU burnt while idle. Waking a
  /// sleeping worker costs a thread wake-up (on the 2-vCPU VM of the README:
  /// ~30 us median, 60-100 us p99, bench/bench_wakeup.cpp); polling avoids it
  /// for batches that come within the window, at the price of cores kept
  /// busy (power).
  int idle_spin_us = -1;

  /// Period of the progress line (spdlog info); 0 = only the final summary.
  double stats_period_s = 1.0;

  /// Paced replays (ReplaySource::set_packet_us): events are handed over in
  /// packets of this period, microseconds, 0..1000000 (0: none).
  int replay_packet_us = 100;

  /// CPU pinning, SCHED_FIFO, locked memory (Engine::run(); off by default).
  RealtimeOptions realtime;
};

/// The one declaration of the engine's numeric options (see
/// evlife/algo/option_info.h): f(info, accessor) per field. The `engine:` keys
/// of config/, validate_engine_options() and `evlife run`'s flags and --help
/// read it. The overload policy (an enum, "auto" | "block" | "drop") is the
/// one option outside it: see kPolicyKey.
template <typename F>
void for_each_engine_option(F&& f) {
  f(OptionInfo{"workers", "workers", 1, 32, false, false, false, false,
               "worker threads"}, [](auto& o) -> auto& { return o.workers; });
  f(OptionInfo{"tiles_x", "", 1, 256, false, false, false, false,
               "tiles per polarity, columns (flag: --tiles CxR)"}, [](auto& o) -> auto& { return o.tiles_x; });
  f(OptionInfo{"tiles_y", "", 1, 256, false, false, false, false,
               "tiles per polarity, rows (flag: --tiles CxR)"}, [](auto& o) -> auto& { return o.tiles_y; });
  f(OptionInfo{"margin_px", "margin", 0, 1024, false, false, false, true,
               "pixels a worker also processes around its tiles; -1: 4 x N"},
    [](auto& o) -> auto& { return o.margin_px; });
  f(OptionInfo{"batch_events", "batch-events", 16, 65536, false, false, false, false,
               "events per batch through the queues"}, [](auto& o) -> auto& { return o.batch_events; });
  f(OptionInfo{"batches_per_worker", "queue-batches", 2, 1024, false, false, false, false,
               "batches in flight per worker"}, [](auto& o) -> auto& { return o.batches_per_worker; });
  f(OptionInfo{"stats_period_s", "stats-period", 0.0, 3600.0, false, false, false, false,
               "progress line (% of a file, ETA, counts) every T; 0: none"},
    [](auto& o) -> auto& { return o.stats_period_s; });
  f(OptionInfo{"idle_spin_us", "idle-spin-us", 0, 100000, false, false, false, true,
               "idle worker polls this long before sleeping, us; -1: auto"},
    [](auto& o) -> auto& { return o.idle_spin_us; });
  f(OptionInfo{"replay_packet_us", "packet-us", 0, 1000000, false, false, false, false,
               "paced replays: packet period, us; 0: none"},
    [](auto& o) -> auto& { return o.replay_packet_us; });
}

/// stats_period_s beyond its range: 0 (no progress lines) or a period that
/// --stats-period's parser would take (rounding to at least 1 us). nullopt
/// when valid, else why not (one rule for the flag's and the key's errors).
inline std::optional<std::string> stats_period_problem(double seconds) {
  if (!(seconds > 0.0 && seconds < 0.5e-6)) return std::nullopt;
  return "must be 0 (no progress lines) or at least 1e-06 (1 us; from 5e-07 it rounds to 1 us)";
}

/// The overload policy's configuration key and its values.
inline constexpr std::string_view kPolicyKey = "policy";

/// "auto", "block" or "drop" into the two fields; false (fields unchanged)
/// for anything else.
inline bool parse_overload_policy(std::string_view text, bool& auto_policy,
                                  OverloadPolicy& policy) {
  if (text != "auto" && text != "block" && text != "drop") return false;
  auto_policy = text == "auto";
  if (!auto_policy) policy = text == "block" ? OverloadPolicy::block : OverloadPolicy::drop;
  return true;
}

inline std::string_view overload_policy_name(bool auto_policy, OverloadPolicy policy) {
  return auto_policy ? "auto" : policy == OverloadPolicy::block ? "block" : "drop";
}

/// Margin actually used for `options` (resolves -1 and the 1x1 case).
int effective_margin_px(const EngineOptions& options);

/// Idle polling of the automatic setting for live sources: a packet period
/// of a camera-like source (100 us), so a worker stays awake between packets.
inline constexpr int kAutoIdleSpinUs = 100;

/// Idle polling actually used (resolves -1 by whether the source is live).
int effective_idle_spin_us(const EngineOptions& options, bool live_source);

/// Empty when usable, else a message naming the field and its allowed range.
std::string validate_engine_options(const EngineOptions& options);

}  // namespace evlife::engine
