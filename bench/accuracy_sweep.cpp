// Accuracy of the estimator on the README's synthetic scenes (the ones
// test_lifetime_accuracy asserts floors on) for any options or seeds: the
// figures of the options and seeds that were measured and not adopted.
//
//   build/bench/accuracy_sweep [--ideal | --textured] [--seed-offset N] [--config FILE] [--set key=value ...]
//                              [--pixel name=value ...] [--noise-rate R] [--bands] [--error-shares] [--why]
//
// --pixel and --noise-rate change the pixel-model scenes' sensor (names as
// `evlife synth`'s pixel options, e.g. --pixel latency-jitter-us=1000): how
// the estimator holds across the range real sensors span. --bands adds each
// scene's rows by true lifetime. --why adds, per scene, why events got no
// lifetime by kind of event (tests/support/rejection_breakdown.h).
// Prints one row per scene: share with a lifetime, median and p90 relative
// lifetime error, median direction error, share of noise labelled noise
// (noise%: the scored noise, without the events within an edge's burst time
// at their pixel and polarity, indistinguishable from its followers;
// all_noise%: every noise event).
#include <cstdio>
#include <cstring>
#include <cstdlib>
#include <exception>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "accuracy_metrics.h"
#include "accuracy_scenes.h"
#include "rejection_breakdown.h"
#include "evlife/algo/lifetime_estimator.h"
#include "evlife/algo/parse_text.h"
#include "evlife/config/config.h"

namespace {

int usage() {
  std::fprintf(stderr,
               "usage: accuracy_sweep [--ideal | --textured] [--seed-offset N] [--config FILE] [--set key=value ...]\n"
               "                      [--pixel name=value ...] [--noise-rate R] [--bands] [--error-shares] [--why]\n"
               "  realistic DVS pixels (normal and dim light) by default, --ideal for the ideal scenes,\n"
               "  --textured for a translating dead-leaves texture through those pixels;\n"
               "  keys as in config/evlife.yaml, e.g. --set estimator.lambda_decay_per_us=0.005;\n"
               "  --pixel changes the pixel model of both settings (names as evlife synth's pixel\n"
               "  options:");
  int column = 10;
  for (const evlife::io::PixelParameter& p : evlife::io::pixel_parameters()) {
    const int width = 1 + static_cast<int>(std::strlen(p.name));
    if (column + width > 86) {
      std::fprintf(stderr, "\n ");
      column = 2;
    }
    std::fprintf(stderr, " %s", p.name);
    column += width;
  }
  std::fprintf(stderr,
               "),\n"
               "  --noise-rate their background activity (events per pixel per second); --bands: also\n"
               "  the rows by true lifetime; --error-shares: three more columns, the shares of the edge\n"
               "  events with a lifetime within 30 %% of the truth (w30%%) and more than 100 %% off\n"
               "  (off100%%), which a share and a median hide, the median signed error (bias%%:\n"
               "  < 0, lifetimes short) and the share of all events after the warm-up with a\n"
               "  lifetime (all%%: edge and noise, any margin, as a recording's share); --why: per scene,\n"
               "  what the estimator did with each kind of event after the warm-up (edge events past\n"
               "  a window's width of travel): fit%% its own plane, follow%% its burst's estimate, or noise for\n"
               "  few%% too few past events, noplane%% no plane with support, unres%% an implausible fit.\n"
               "  noise%% leaves out noise events within an edge's burst time at their pixel and polarity\n"
               "  (half a lifetime before an edge event to 2 after: a burst follower's); all_noise%% counts them\n");
  return 2;
}

// Applies "name=value" to the pixel model; false for an unknown name or a
// value outside the parameter's range.
bool set_pixel_parameter(const std::string& assignment, evlife::io::PixelModel& pixel) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos) return false;
  const std::string name = assignment.substr(0, eq);
  const std::optional<double> value = evlife::parse_decimal(std::string_view(assignment).substr(eq + 1));
  if (!value) return false;
  for (const evlife::io::PixelParameter& p : evlife::io::pixel_parameters()) {
    if (name != p.name) continue;
    if (!(*value >= p.lo && *value <= p.hi)) return false;
    pixel.*p.field = *value;
    return true;
  }
  return false;
}

}  // namespace

int main(int argc, char** argv) try {
  evlife::config::ConfigBuilder builder;
  bool ideal = false;
  bool textured = false;
  bool bands = false;
  bool error_shares = false;
  bool why = false;
  unsigned seed_offset = 0;
  std::vector<std::string> pixel_assignments;
  double noise_rate_hz_per_px = -1.0;  // < 0: each setting's own
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--ideal") {
      ideal = true;
    } else if (arg == "--textured") {
      textured = true;
    } else if (arg == "--bands") {
      bands = true;
    } else if (arg == "--error-shares") {
      error_shares = true;
    } else if (arg == "--why") {
      why = true;
    } else if (arg == "--seed-offset" && has_value) {
      seed_offset = static_cast<unsigned>(std::strtoul(argv[++i], nullptr, 10));
    } else if (arg == "--config" && has_value) {
      builder.load_file(argv[++i]);
    } else if (arg == "--set" && has_value) {
      builder.set(argv[++i]);
    } else if (arg == "--pixel" && has_value) {
      pixel_assignments.emplace_back(argv[++i]);
    } else if (arg == "--noise-rate" && has_value) {
      const std::optional<double> rate = evlife::parse_decimal(argv[++i]);
      if (!rate || !(*rate >= 0.0)) return usage();
      noise_rate_hz_per_px = *rate;
    } else {
      return usage();
    }
  }
  const evlife::LifetimeOptions options = builder.build().estimator;
  if (ideal && (textured || !pixel_assignments.empty() || noise_rate_hz_per_px >= 0.0)) return usage();
  auto scenes = ideal      ? evlife::test::ideal_accuracy_scenes(seed_offset)
                : textured ? evlife::test::textured_accuracy_scenes(seed_offset)
                           : evlife::test::pixel_model_accuracy_scenes(seed_offset);
  for (auto& scene : scenes) {
    for (const std::string& a : pixel_assignments) {
      if (!set_pixel_parameter(a, scene.pixel())) {
        std::fprintf(stderr, "accuracy_sweep: --pixel %s: unknown name or value out of range\n", a.c_str());
        return 2;
      }
    }
    if (noise_rate_hz_per_px >= 0.0) scene.noise_rate_hz_per_px() = noise_rate_hz_per_px;
  }
  // One thread per scene: each generates, estimates and scores its own.
  std::vector<evlife::test::AccuracyReport> reports(scenes.size());
  std::vector<std::string> breakdowns(scenes.size());
  std::vector<std::thread> threads;
  for (std::size_t k = 0; k < scenes.size(); ++k) {
    threads.emplace_back([&, k] {
      const evlife::io::SyntheticScene scene = scenes[k].generate();
      evlife::LifetimeOptions o = options;
      o.sensor = scene.spec.sensor;
      evlife::LifetimeEstimator estimator(o);
      std::vector<evlife::AugmentedEvent> out(scene.events.size());
      estimator.process(scene.events, out);
      evlife::test::AccuracyOptions metric;
      metric.window_size = o.window_size;
      reports[k] = evlife::test::evaluate_accuracy(scene, out, metric);
      if (why) {
        breakdowns[k] = evlife::test::format_breakdown(scenes[k].title,
                                                       evlife::test::rejection_breakdown(scene, options, metric));
      }
    });
  }
  for (auto& t : threads) t.join();
  // Noise is scored per scene, not per band: a band row prints "-" there.
  const auto print_row = [&](const std::string& title, const evlife::test::AccuracyMetrics& r, bool with_noise) {
    std::printf("%-62s %8.2f %8.2f %8.2f %8.2f", title.c_str(), 100.0 * r.lifetime_share, 100.0 * r.median_rel_error,
                100.0 * r.p90_rel_error, r.median_dir_error_deg);
    if (with_noise) {
      std::printf(" %8.2f", 100.0 * r.noise_share);
    } else {
      std::printf(" %8s", "-");
    }
    if (error_shares) {
      std::printf(" %8.2f %8.2f %8.2f", 100.0 * r.share_within_30_percent, 100.0 * r.share_off_by_over_100_percent,
                  100.0 * r.median_signed_rel_error);
      if (with_noise) {
        std::printf(" %8.2f", 100.0 * r.all_events_lifetime_share);
      } else {
        std::printf(" %8s", "-");
      }
    }
    // Noise over all noise events, those within an edge's burst time at their pixel too (noise% leaves them out).
    if (with_noise) {
      const std::size_t all = r.noise_events + r.noise_indistinguishable;
      std::printf(" %10.2f", all ? 100.0 * double(r.noise_labelled_noise + r.noise_indistinguishable_labelled_noise) /
                                       double(all)
                                 : std::nan(""));
    } else {
      std::printf(" %10s", "-");
    }
    std::printf("\n");
  };
  std::printf("%-62s %8s %8s %8s %8s %8s", "scene", "share%", "med%", "p90%", "dir_deg", "noise%");
  if (error_shares) std::printf(" %8s %8s %8s %8s", "w30%", "off100%", "bias%", "all%");
  std::printf(" %10s\n", "all_noise%");
  for (std::size_t k = 0; k < scenes.size(); ++k) print_row(scenes[k].title, reports[k].overall, true);
  if (bands) {
    for (std::size_t k = 0; k < scenes.size(); ++k) {
      std::printf("\n%s, by true lifetime (share of events%% in the band first):\n", scenes[k].title.c_str());
      for (const auto& band : reports[k].per_lifetime) {
        char title[96];
        std::snprintf(title, sizeof title, "  %-30s %5.1f%%", band.label.c_str(),
                      100.0 * static_cast<double>(band.edge_events) /
                          static_cast<double>(reports[k].overall.edge_events));
        print_row(title, band, false);
      }
    }
  }
  if (why) {
    for (const std::string& b : breakdowns) std::printf("\n%s", b.c_str());
  }
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "accuracy_sweep: %s\n", e.what());
  return 1;
}
