// Why events get no lifetime, by kind of event: a synthetic scene run through
// the estimator one event at a time, each event's outcome read from the
// estimator's counters (LifetimeStats) before and after it. Separates what
// the shares of accuracy_metrics.h lump together: an edge's first event in a
// burst and its followers, edges where the surface is a plane (scorable) and
// where it is not (curved iso-lines, junctions, a rotation centre), noise.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "accuracy_metrics.h"
#include "evlife/algo/lifetime_options.h"
#include "evlife/io/synthetic_scene.h"

namespace evlife::test {

/// What the estimator did with an event.
enum class Outcome : std::size_t { lifetime, follower, few_samples, unsupported, unresolved, count };

struct BreakdownRow {
  std::string kind;
  std::size_t events = 0;
  std::array<std::size_t, static_cast<std::size_t>(Outcome::count)> outcomes{};  ///< indexed by Outcome
};

/// Rows: edge first events on a plane, first events off a plane (not
/// scorable), burst followers (burst_index > 0), background activity, hot
/// pixels. The events evaluate_accuracy() would look at: after
/// metric.warmup_us; edge events once their edge has moved
/// metric.min_travel_windows windows and where their window lies in their
/// feature's region (the estimator's window_size sets both). A "lifetime"
/// outcome is a fit of the event's own window; "follower" an estimate
/// inherited from its burst.
std::vector<BreakdownRow> rejection_breakdown(const io::SyntheticScene& scene, const LifetimeOptions& options,
                                              const AccuracyOptions& metric = {});

/// The rows as a text table (shares of each row's events, in %).
std::string format_breakdown(const std::string& title, const std::vector<BreakdownRow>& rows);

}  // namespace evlife::test
