// Accuracy of augmented events against a synthetic scene's ground truth: the
// figures the issue sets floors for (share of edge events given a lifetime,
// relative lifetime error, direction error, share of noise labelled noise).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "evlife/algo/event.h"
#include "evlife/io/synthetic_scene.h"

namespace evlife::test {

struct AccuracyOptions {
  /// Window side N of the estimator: only events whose N x N window lies
  /// inside their feature's region (margin >= N/2) are scored.
  int window_size = 5;
  /// Events before this time are not scored (history and predictions build up).
  std::int64_t warmup_us = 50'000;
  /// Edge events are scored once their edge has moved this many windows (N px)
  /// since its motion began: before that the window cannot hold a plane's
  /// worth of past events (a start-up effect like the warm-up, per edge).
  double min_travel_windows = 1.0;
  /// A noise event from half a lifetime before to this many lifetimes after an
  /// edge event at its pixel and polarity is indistinguishable from a burst
  /// follower (real pixels fire several events per edge over ~2 lifetimes;
  /// the estimator's estimator.burst_window_lifetimes): not scored.
  double burst_window_lifetimes = 2.0;
};

struct AccuracyMetrics {
  std::string label;
  std::size_t edge_events = 0;         ///< scored edge events
  std::size_t edge_onset_skipped = 0;  ///< overall only: edge events skipped by min_travel_windows
  std::size_t edge_with_lifetime = 0;  ///< of which the estimator gave lifetime > 0
  double lifetime_share = 0.0;         ///< edge_with_lifetime / edge_events
  // Over scored edge events that got a lifetime:
  double median_rel_error = 0.0;       ///< |tau - tau_true| / tau_true
  double p90_rel_error = 0.0;
  double median_signed_rel_error = 0.0;  ///< (tau - tau_true) / tau_true: the bias
  double median_dir_error_deg = 0.0;   ///< angle between velocity and true motion normal
  double p90_dir_error_deg = 0.0;
  // Over all scored edge events (a share and a median hide far-off lifetimes):
  double share_within_30_percent = 0.0;     ///< with a lifetime within 30 % of the truth
  double share_off_by_over_100_percent = 0.0;  ///< with a lifetime more than twice off the truth
  // Noise (overall row only):
  std::size_t noise_events = 0;        ///< scored noise events (distinguishable ones)
  std::size_t noise_indistinguishable = 0;  ///< within the burst window of an edge event, same pixel+polarity
  std::size_t noise_labelled_noise = 0;
  std::size_t noise_indistinguishable_labelled_noise = 0;  ///< of the indistinguishable, labelled noise
  double noise_share = 0.0;            ///< noise_labelled_noise / noise_events
  /// Overall row only: the share of all events after the warm-up (edge,
  /// noise, any margin or scorability) with a lifetime: what a recording's
  /// "share with a lifetime" measures.
  double all_events_lifetime_share = 0.0;
};

struct AccuracyReport {
  AccuracyMetrics overall;
  std::vector<AccuracyMetrics> per_feature;   ///< one row per grating / bar
  std::vector<AccuracyMetrics> per_lifetime;  ///< rows by true-lifetime band
};

/// `out[i]` must be the estimator's output for `scene.events[i]`.
AccuracyReport evaluate_accuracy(const io::SyntheticScene& scene, std::span<const AugmentedEvent> out,
                                 const AccuracyOptions& options = {});

/// A fixed-width text table: overall, then per lifetime band and per feature.
std::string format_accuracy_table(const std::string& title, const AccuracyReport& report);

}  // namespace evlife::test
