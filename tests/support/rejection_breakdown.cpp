#include "rejection_breakdown.h"

#include <cstdio>

#include "evlife/algo/lifetime_estimator.h"

namespace evlife::test {
namespace {

enum Kind : std::size_t { kFirstOnPlane, kFirstOffPlane, kFollower, kBackground, kHot, kKinds };

// The counter that moved while the estimator took one event.
Outcome outcome_of(const LifetimeStats& before, const LifetimeStats& after, const AugmentedEvent& out) {
  if (after.noise_few_samples != before.noise_few_samples) return Outcome::few_samples;
  if (after.noise_unsupported != before.noise_unsupported) return Outcome::unsupported;
  if (after.noise_unresolved != before.noise_unresolved) return Outcome::unresolved;
  if (!(out.lifetime_us > 0.0f)) return Outcome::unresolved;  // no other path gives lifetime 0 in the sensor
  return after.followers != before.followers ? Outcome::follower : Outcome::lifetime;
}

}  // namespace

std::vector<BreakdownRow> rejection_breakdown(const io::SyntheticScene& scene, const LifetimeOptions& options,
                                              const AccuracyOptions& metric) {
  LifetimeOptions o = options;
  o.sensor = scene.spec.sensor;
  LifetimeEstimator estimator(o);
  std::vector<BreakdownRow> rows(kKinds);
  rows[kFirstOnPlane].kind = "edge, first event of its burst, on a plane";
  rows[kFirstOffPlane].kind = "edge, first event, off a plane (curved, junction)";
  rows[kFollower].kind = "edge, burst follower";
  rows[kBackground].kind = "background activity";
  rows[kHot].kind = "hot pixel";
  const int margin = o.window_size / 2;
  const double min_travel_px = metric.min_travel_windows * o.window_size;
  for (std::size_t i = 0; i < scene.events.size(); ++i) {
    const LifetimeStats before = estimator.stats();
    const AugmentedEvent out = estimator.process(scene.events[i]);
    const io::EventTruth& truth = scene.truth[i];
    if (scene.events[i].t_us < metric.warmup_us) continue;
    std::size_t kind = kKinds;
    if (truth.is_noise) {
      kind = truth.is_hot ? kHot : kBackground;
    } else if (truth.margin_px >= margin && truth.travel_px >= min_travel_px) {
      kind = truth.burst_index > 0 ? kFollower : truth.scorable ? kFirstOnPlane : kFirstOffPlane;
    }
    if (kind == kKinds) continue;
    ++rows[kind].events;
    ++rows[kind].outcomes[static_cast<std::size_t>(outcome_of(before, estimator.stats(), out))];
  }
  return rows;
}

std::string format_breakdown(const std::string& title, const std::vector<BreakdownRow>& rows) {
  std::size_t total = 0;
  for (const BreakdownRow& r : rows) total += r.events;
  std::string text = title + "\n";
  char line[256];
  std::snprintf(line, sizeof line, "  %-50s %8s %8s | %8s %8s | %8s %8s %8s\n", "kind (after the warm-up)", "events",
                "share%", "fit%", "follow%", "few%", "noplane%", "unres%");
  text += line;
  for (const BreakdownRow& r : rows) {
    if (r.events == 0) continue;
    const auto pct = [&](Outcome o) {
      return 100.0 * static_cast<double>(r.outcomes[static_cast<std::size_t>(o)]) / static_cast<double>(r.events);
    };
    std::snprintf(line, sizeof line, "  %-50s %8zu %8.2f | %8.2f %8.2f | %8.2f %8.2f %8.2f\n", r.kind.c_str(), r.events,
                  100.0 * static_cast<double>(r.events) / static_cast<double>(total), pct(Outcome::lifetime),
                  pct(Outcome::follower), pct(Outcome::few_samples), pct(Outcome::unsupported),
                  pct(Outcome::unresolved));
    text += line;
  }
  return text;
}

}  // namespace evlife::test
