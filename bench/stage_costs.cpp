// Per-stage cost of LifetimeEstimator::process(), per event, default options:
// the estimator's sources compiled again with EVLIFE_ESTIMATOR_STAGE_CLOCK
// (algo/src/stage_clock.h: a time-stamp counter read at each stage's end).
// The counter's ticks split the process CPU time of each run (the machine
// may be shared): a stage's ns/event is over all events (a stage few events
// reach costs little), "events" the share that passes through it; medians of
// 7 runs. The counter reads themselves add some ns per stage.
//   ./build/bench/bench_estimator_stages [stripes garfield synthetic_1280x720]
// (the recordings of bench_recordings.h: a reference recording's name, or
// synthetic_WxH).
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <exception>
#include <string>
#include <vector>

#include "bench_recordings.h"
#include "evlife/algo/lifetime_estimator.h"
#include "stage_clock.h"

namespace {

using evlife::detail::Stage;
constexpr int kStages = static_cast<int>(Stage::count);
constexpr const char* kNames[kStages] = {"head (checks, follower, prediction)", "gather (window, newer half)",
                                         "select (padding)", "ransac", "continuation",
                                         "refit (least squares)", "tail (burst state, rms, next prediction)"};

double cpu_ns() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e9 + static_cast<double>(ts.tv_nsec);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

void report(const std::string& name) {
  const evlife::bench::Recording& rec = evlife::bench::recording(name);
  evlife::LifetimeOptions o;
  o.sensor = rec.sensor;
  evlife::LifetimeEstimator est(o);
  std::vector<evlife::AugmentedEvent> out(rec.events.size());
  const double n = static_cast<double>(rec.events.size());
  constexpr int kRuns = 7;
  std::vector<double> per_stage[kStages], total;
  std::uint64_t entered[kStages] = {};
  for (int run = 0; run < kRuns; ++run) {
    est.reset();
    auto& clock = evlife::detail::stage_clock();
    clock = {};
    const double t0 = cpu_ns();
    est.process(rec.events, out);
    const double ns = cpu_ns() - t0;
    std::uint64_t ticks = 0;
    for (const std::uint64_t t : clock.ticks) ticks += t;
    const double ns_per_tick = ns / static_cast<double>(ticks);
    for (int s = 0; s < kStages; ++s) {
      per_stage[s].push_back(static_cast<double>(clock.ticks[s]) * ns_per_tick / n);
      entered[s] = clock.entered[s];
    }
    total.push_back(ns / n);
  }
  std::printf("%s: %.0f events, instrumented %.0f ns/event CPU time (median of %d)\n", name.c_str(), n, median(total), kRuns);
  std::printf("  %-44s %8s %10s\n", "stage", "ns/event", "events");
  for (int s = 0; s < kStages; ++s) {
    std::printf("  %-44s %8.1f %9.1f%%\n", kNames[s], median(per_stage[s]), 100.0 * static_cast<double>(entered[s]) / n);
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> names(argv + 1, argv + argc);
  for (const auto& name : names) {
    if (name == "--help" || name == "-h") {
      std::printf("usage: bench_estimator_stages [RECORDING...]\n\n"
                  "The estimator's cost per stage (ns/event over all events, and the share of events\n"
                  "reaching each stage), default options, medians of 7 runs, with a stage clock\n"
                  "compiled in: read the figures as shares, not as times (bench/README.md).\n"
                  "RECORDING: stripes, garfield (../shared/data/reference/NAME.mat) or synthetic_WxH\n"
                  "(the `large` scene on a WxH sensor); default: stripes garfield synthetic_1280x720.\n");
      return 0;
    }
  }
  if (names.empty()) names = {"stripes", "garfield", "synthetic_1280x720"};
  for (const auto& name : names) {
    try {
      report(name);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "bench_estimator_stages: %s: %s (--help)\n", name.c_str(), e.what());
      return 1;
    }
  }
  return 0;
}
