// Ground-truth scoring of augmented events (see accuracy_metrics.h).
#include "accuracy_metrics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

namespace evlife::test {
namespace {

// Upper bounds of the lifetime bands of the per-lifetime rows, microseconds.
constexpr std::array<double, 7> kBandUpperUs{500, 1000, 2000, 5000, 10000, 20000, 1e300};

struct Samples {
  std::size_t edge_events = 0;
  std::size_t edge_with_lifetime = 0;
  std::vector<double> rel_error, signed_rel_error, dir_error_deg;

  void add(const io::EventTruth& truth, const AugmentedEvent& a) {
    ++edge_events;
    if (a.is_noise()) return;
    ++edge_with_lifetime;
    const double tau = static_cast<double>(a.lifetime_us), tau_true = truth.lifetime_us;
    const double vx = static_cast<double>(a.vx_px_s), vy = static_cast<double>(a.vy_px_s);
    rel_error.push_back(std::abs(tau - tau_true) / tau_true);
    signed_rel_error.push_back((tau - tau_true) / tau_true);
    const double speed = std::hypot(vx, vy);
    double cos_angle = -1.0;  // no velocity at all counts as the worst direction
    if (speed > 0.0) cos_angle = (vx * truth.nx + vy * truth.ny) / speed;
    dir_error_deg.push_back(std::acos(std::clamp(cos_angle, -1.0, 1.0)) * 180.0 / std::numbers::pi);
  }
};

double quantile(std::vector<double>& v, double q) {
  if (v.empty()) return std::nan("");
  const auto k = static_cast<std::size_t>(std::lround(q * static_cast<double>(v.size() - 1)));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

AccuracyMetrics summarize(std::string label, Samples& s) {
  AccuracyMetrics m;
  m.label = std::move(label);
  m.edge_events = s.edge_events;
  m.edge_with_lifetime = s.edge_with_lifetime;
  m.lifetime_share = s.edge_events ? double(s.edge_with_lifetime) / double(s.edge_events) : std::nan("");
  const auto share_of_edges = [&](auto pred) {
    return s.edge_events ? double(std::count_if(s.rel_error.begin(), s.rel_error.end(), pred)) / double(s.edge_events)
                         : std::nan("");
  };
  m.share_within_30_percent = share_of_edges([](double e) { return e <= 0.3; });
  m.share_off_by_over_100_percent = share_of_edges([](double e) { return e > 1.0; });
  m.median_rel_error = quantile(s.rel_error, 0.5);
  m.p90_rel_error = quantile(s.rel_error, 0.9);
  m.median_signed_rel_error = quantile(s.signed_rel_error, 0.5);
  m.median_dir_error_deg = quantile(s.dir_error_deg, 0.5);
  m.p90_dir_error_deg = quantile(s.dir_error_deg, 0.9);
  return m;
}

std::string band_label(std::size_t b) {
  const double lo = b == 0 ? 0.0 : kBandUpperUs[b - 1];
  char buf[64];
  if (b + 1 == kBandUpperUs.size()) {
    std::snprintf(buf, sizeof buf, "lifetime >= %.0f us", lo);
  } else {
    std::snprintf(buf, sizeof buf, "lifetime %.0f..%.0f us", lo, kBandUpperUs[b]);
  }
  return buf;
}

// Edge events per (pixel, polarity), by time: a noise event from half a
// lifetime before one of them to the end of its burst window cannot be told
// apart from it (an edge event or a burst follower).
class EdgeIndex {
 public:
  EdgeIndex(const io::SyntheticScene& scene, double burst_window_lifetimes)
      : burst_window_lifetimes_(std::max(0.5, burst_window_lifetimes)) {
    for (std::size_t i = 0; i < scene.events.size(); ++i) {
      if (scene.truth[i].is_noise) continue;
      const Event& e = scene.events[i];
      entries_.push_back({key(e, scene.spec.sensor), e.t_us, scene.truth[i].lifetime_us});
    }
    std::sort(entries_.begin(), entries_.end(), [](const Entry& a, const Entry& b) {
      return a.key != b.key ? a.key < b.key : a.t_us < b.t_us;
    });
  }
  bool near_edge(const Event& e, SensorSize sensor) const {
    const std::uint64_t k = key(e, sensor);
    auto it = std::lower_bound(entries_.begin(), entries_.end(), std::pair{k, e.t_us},
                               [](const Entry& a, const std::pair<std::uint64_t, std::int64_t>& b) {
                                 return a.key != b.first ? a.key < b.first : a.t_us < b.second;
                               });
    // The two nearest edge events on each side are enough: lifetimes of one
    // pixel change slowly.
    const auto pos = static_cast<std::size_t>(it - entries_.begin());
    for (std::size_t step = 0; step < 2; ++step) {
      const std::size_t after = pos + step;
      if (after < entries_.size() && entries_[after].key == k && close(entries_[after], e)) return true;
      if (pos >= step + 1) {
        const std::size_t before = pos - step - 1;
        if (entries_[before].key == k && close(entries_[before], e)) return true;
      }
    }
    return false;
  }

 private:
  struct Entry {
    std::uint64_t key;
    std::int64_t t_us;
    double lifetime_us;
  };
  static std::uint64_t key(const Event& e, SensorSize s) {
    return (static_cast<std::uint64_t>(e.y) * static_cast<std::uint64_t>(s.width) + e.x) * 2 +
           (e.p > 0 ? 1 : 0);
  }
  bool close(const Entry& edge, const Event& e) const {
    const auto after_us = static_cast<double>(e.t_us - edge.t_us);
    return after_us > -0.5 * edge.lifetime_us && after_us < burst_window_lifetimes_ * edge.lifetime_us;
  }
  double burst_window_lifetimes_;
  std::vector<Entry> entries_;
};

}  // namespace

AccuracyReport evaluate_accuracy(const io::SyntheticScene& scene, std::span<const AugmentedEvent> out,
                                 const AccuracyOptions& options) {
  if (out.size() != scene.events.size() || scene.truth.size() != scene.events.size()) {
    throw std::invalid_argument("evaluate_accuracy: output, events and truth differ in size");
  }
  const int margin = options.window_size / 2;
  Samples overall;
  std::vector<Samples> per_feature(scene.feature_names.size());
  std::vector<Samples> per_band(kBandUpperUs.size());
  AccuracyReport report;
  const EdgeIndex edges(scene, options.burst_window_lifetimes);
  std::size_t onset_skipped = 0;
  std::size_t after_warmup = 0, after_warmup_with_lifetime = 0;

  for (std::size_t i = 0; i < scene.events.size(); ++i) {
    const Event& e = scene.events[i];
    const io::EventTruth& truth = scene.truth[i];
    if (e.t_us >= options.warmup_us) {
      ++after_warmup;
      if (!out[i].is_noise()) ++after_warmup_with_lifetime;
    }
    if (e.t_us < options.warmup_us || truth.margin_px < margin) continue;
    if (truth.is_noise) {
      if (edges.near_edge(e, scene.spec.sensor)) {
        ++report.overall.noise_indistinguishable;
        if (out[i].is_noise()) ++report.overall.noise_indistinguishable_labelled_noise;
        continue;
      }
      ++report.overall.noise_events;
      if (out[i].is_noise()) ++report.overall.noise_labelled_noise;
      continue;
    }
    if (!truth.scorable) continue;
    if (truth.travel_px < options.min_travel_windows * options.window_size) {
      ++onset_skipped;
      continue;
    }
    overall.add(truth, out[i]);
    if (truth.feature >= 0 && static_cast<std::size_t>(truth.feature) < per_feature.size()) {
      per_feature[static_cast<std::size_t>(truth.feature)].add(truth, out[i]);
    }
    std::size_t band = 0;
    while (truth.lifetime_us >= kBandUpperUs[band]) ++band;
    per_band[band].add(truth, out[i]);
  }

  const AccuracyMetrics noise = report.overall;
  report.overall = summarize("all edges", overall);
  report.overall.edge_onset_skipped = onset_skipped;
  report.overall.noise_events = noise.noise_events;
  report.overall.noise_indistinguishable = noise.noise_indistinguishable;
  report.overall.noise_labelled_noise = noise.noise_labelled_noise;
  report.overall.noise_indistinguishable_labelled_noise = noise.noise_indistinguishable_labelled_noise;
  report.overall.noise_share =
      noise.noise_events ? double(noise.noise_labelled_noise) / double(noise.noise_events) : std::nan("");
  report.overall.all_events_lifetime_share =
      after_warmup ? double(after_warmup_with_lifetime) / double(after_warmup) : std::nan("");
  for (std::size_t b = 0; b < per_band.size(); ++b) {
    if (per_band[b].edge_events) report.per_lifetime.push_back(summarize(band_label(b), per_band[b]));
  }
  for (std::size_t f = 0; f < per_feature.size(); ++f) {
    if (per_feature[f].edge_events) {
      report.per_feature.push_back(summarize(scene.feature_names[f], per_feature[f]));
    }
  }
  return report;
}

std::string format_accuracy_table(const std::string& title, const AccuracyReport& report) {
  std::string s = "== " + title + " ==\n";
  char line[512];
  std::snprintf(line, sizeof line, "%-44s %8s %7s %8s %8s %8s %7s %7s\n", "edges", "events",
                "w/ tau%", "med rel%", "p90 rel%", "bias%", "med dir", "p90 dir");
  s += line;
  auto row = [&](const AccuracyMetrics& m) {
    std::snprintf(line, sizeof line, "%-44.44s %8zu %7.2f %8.2f %8.2f %+8.2f %7.2f %7.2f\n",
                  m.label.c_str(), m.edge_events, 100.0 * m.lifetime_share, 100.0 * m.median_rel_error,
                  100.0 * m.p90_rel_error, 100.0 * m.median_signed_rel_error, m.median_dir_error_deg,
                  m.p90_dir_error_deg);
    s += line;
  };
  row(report.overall);
  for (const auto& m : report.per_lifetime) row(m);
  for (const auto& m : report.per_feature) row(m);
  const auto& o = report.overall;
  const std::size_t all_noise = o.noise_events + o.noise_indistinguishable;
  std::snprintf(line, sizeof line,
                "noise: %zu scored, %.2f%% labelled noise (%zu indistinguishable from edges, not scored; "
                "all %zu: %.2f%%); %zu edge events at motion onset not scored\n",
                o.noise_events, 100.0 * o.noise_share, o.noise_indistinguishable, all_noise,
                all_noise ? 100.0 * double(o.noise_labelled_noise + o.noise_indistinguishable_labelled_noise) /
                                double(all_noise)
                          : std::nan(""),
                o.edge_onset_skipped);
  s += line;
  return s;
}

}  // namespace evlife::test
