// Accuracy of the estimator on the README's synthetic scenes (the ones
// test_lifetime_accuracy asserts floors on) for any options or seeds: the
// figures of the options and seeds that were measured and not adopted.
//
//   build/bench/accuracy_sweep [--ideal] [--seed-offset N] [--config FILE] [--set key=value ...]
//
// Prints one row per scene: share with a lifetime, median and p90 relative
// lifetime error, median direction error, share of noise labelled noise.
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <thread>
#include <vector>

#include "accuracy_metrics.h"
#include "accuracy_scenes.h"
#include "evlife/algo/lifetime_estimator.h"
#include "evlife/config/config.h"

namespace {

int usage() {
  std::fprintf(stderr,
               "usage: accuracy_sweep [--ideal] [--seed-offset N] [--config FILE] [--set key=value ...]\n"
               "  realistic DVS pixels (normal and dim light) by default, --ideal for the ideal scenes;\n"
               "  keys as in config/evlife.yaml, e.g. --set estimator.lambda_decay_per_us=0.005\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) try {
  evlife::config::ConfigBuilder builder;
  bool ideal = false;
  unsigned seed_offset = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--ideal") {
      ideal = true;
    } else if (arg == "--seed-offset" && has_value) {
      seed_offset = static_cast<unsigned>(std::strtoul(argv[++i], nullptr, 10));
    } else if (arg == "--config" && has_value) {
      builder.load_file(argv[++i]);
    } else if (arg == "--set" && has_value) {
      builder.set(argv[++i]);
    } else {
      return usage();
    }
  }
  const evlife::LifetimeOptions options = builder.build().estimator;
  const auto scenes = ideal ? evlife::test::ideal_accuracy_scenes(seed_offset)
                            : evlife::test::pixel_model_accuracy_scenes(seed_offset);
  // One thread per scene: each generates, estimates and scores its own.
  std::vector<evlife::test::AccuracyMetrics> rows(scenes.size());
  std::vector<std::thread> threads;
  for (std::size_t k = 0; k < scenes.size(); ++k) {
    threads.emplace_back([&, k] {
      const evlife::io::SyntheticScene scene = evlife::io::generate_scene(scenes[k].spec);
      evlife::LifetimeOptions o = options;
      o.sensor = scene.spec.sensor;
      evlife::LifetimeEstimator estimator(o);
      std::vector<evlife::AugmentedEvent> out(scene.events.size());
      estimator.process(scene.events, out);
      evlife::test::AccuracyOptions metric;
      metric.window_size = o.window_size;
      rows[k] = evlife::test::evaluate_accuracy(scene, out, metric).overall;
    });
  }
  for (auto& t : threads) t.join();
  std::printf("%-62s %8s %8s %8s %8s %8s\n", "scene", "share%", "med%", "p90%", "dir_deg", "noise%");
  for (std::size_t k = 0; k < scenes.size(); ++k) {
    const auto& r = rows[k];
    std::printf("%-62s %8.2f %8.2f %8.2f %8.2f %8.2f\n", scenes[k].title.c_str(), 100.0 * r.lifetime_share,
                100.0 * r.median_rel_error, 100.0 * r.p90_rel_error, r.median_dir_error_deg, 100.0 * r.noise_share);
  }
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "accuracy_sweep: %s\n", e.what());
  return 1;
}
