#include "lifetime_summary.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace evlife::cli {

LifetimeSummary::LifetimeSummary(std::optional<SensorSize> sensor)
    : lifetime_us_(render::Histogram::log_bins(0.1, 1e9, 100)),  // covers every allowed max_lifetime_us
      abs_error_us_(render::Histogram::log_bins(0.1, 1e10, 100)),
      busy_pixels_(sensor) {}

void LifetimeSummary::add(std::span<const AugmentedEvent> events) noexcept {
  if (!events.empty()) {
    if (events_ == 0) first_t_us_ = events.front().event.t_us;
    last_t_us_ = events.back().event.t_us;
  }
  for (const AugmentedEvent& a : events) {
    ++events_;
    if (a.is_noise()) {
      ++noise_;
    } else {
      lifetime_us_.add(static_cast<double>(a.lifetime_us));
    }
    if (a.has_prediction()) {
      ++predictions_;
      abs_error_us_.add(static_cast<double>(std::fabs(a.prediction_error_us)));
    }
    busy_pixels_.add(a);
  }
}

std::string format_time_range(std::int64_t first_t_us, std::int64_t last_t_us) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "t = %lld .. %lld us (%.6f s long)", static_cast<long long>(first_t_us),
                static_cast<long long>(last_t_us), seconds_between(first_t_us, last_t_us));
  return buf;
}

std::string format_duration_us(double us) {
  char buf[32];
  if (std::isnan(us)) return "-";
  if (us < 1e3) {
    std::snprintf(buf, sizeof buf, "%.3g µs", us);
  } else if (us < 1e6) {
    std::snprintf(buf, sizeof buf, "%.3g ms", us / 1e3);
  } else {
    std::snprintf(buf, sizeof buf, "%.3g s", us / 1e6);
  }
  return buf;
}

std::string format_si(double value) {
  char buf[32];
  if (value >= 1e9) {
    std::snprintf(buf, sizeof buf, "%.3g G", value / 1e9);
  } else if (value >= 1e6) {
    std::snprintf(buf, sizeof buf, "%.3g M", value / 1e6);
  } else if (value >= 1e3) {
    std::snprintf(buf, sizeof buf, "%.3g k", value / 1e3);
  } else {
    std::snprintf(buf, sizeof buf, "%.3g ", value);
  }
  return buf;
}

void LifetimeSummary::print(std::FILE* out, double wall_s, double estimator_s) const {
  std::fprintf(out, "  events              %llu\n", static_cast<unsigned long long>(events_));
  if (events_ > 0) std::fprintf(out, "  time range          %s\n", format_time_range(first_t_us_, last_t_us_).c_str());
  print_lifetimes(out);
  const double n = static_cast<double>(events_);
  std::fprintf(out, "  wall time           %.3f s (%sevents/s end to end", wall_s,
               format_si(wall_s > 0 ? n / wall_s : 0.0).c_str());
  if (estimator_s > 0) {
    std::fprintf(out, "; estimator alone %sevents/s", format_si(n / estimator_s).c_str());
  }
  std::fprintf(out, ")\n");
  print_notes(out);
}

void LifetimeSummary::print_figures(std::FILE* out) const {
  print_lifetimes(out);
  print_notes(out);
}

void LifetimeSummary::print_lifetimes(std::FILE* out) const {
  const auto share = [](std::uint64_t part, std::uint64_t whole) {
    return whole == 0 ? 0.0 : 100.0 * static_cast<double>(part) / static_cast<double>(whole);
  };
  std::fprintf(out, "  labelled noise      %.1f %% (%llu events)\n", share(noise_, events_),
               static_cast<unsigned long long>(noise_));
  if (lifetime_us_.total() > 0) {
    std::fprintf(out, "  lifetime (edges)    p10 %s   p50 %s   p90 %s   p99 %s\n",
                 format_duration_us(lifetime_us_.percentile(0.10)).c_str(),
                 format_duration_us(lifetime_us_.percentile(0.50)).c_str(),
                 format_duration_us(lifetime_us_.percentile(0.90)).c_str(),
                 format_duration_us(lifetime_us_.percentile(0.99)).c_str());
  }
  std::fprintf(out, "  with a prediction   %.1f %% of events\n", share(predictions_, events_));
  if (abs_error_us_.total() > 0) {
    std::fprintf(out, "  |prediction error|  median %s, %.1f %% below 10 ms\n",
                 format_duration_us(abs_error_us_.percentile(0.5)).c_str(),
                 100.0 * abs_error_us_.share_below(1e4));
  }
}

void LifetimeSummary::print_notes(std::FILE* out) const {
  std::fprintf(out, "  (percentiles from a log histogram: ±1.2 %%)\n");
  // A past-only estimator labels an edge's first passage through an empty
  // surface worse than the later ones; recordings need about ten median
  // lifetimes to reach their steady share (algo/README.md, *Warm-up*). Say so when
  // the whole recording is short on that scale, so that a low share is not
  // read as the estimator's steady state. This note and the busy pixels'
  // come last, so that the lines above keep their order for scripts.
  constexpr double kWarmupNoticeLifetimes = 20.0;
  if (lifetime_us_.total() > 0 && last_t_us_ > first_t_us_) {
    const double lifetimes_long =
        seconds_between(first_t_us_, last_t_us_) * 1e6 / std::max(lifetime_us_.percentile(0.50), 1.0);
    if (lifetimes_long < kWarmupNoticeLifetimes) {
      std::fprintf(out,
                   "  warm-up             the recording is %.1f median lifetimes long; in the first ~10 of\n"
                   "                      each region the surface fills and fewer events get a lifetime\n"
                   "                      (algo/README.md, Warm-up)\n",
                   lifetimes_long);
    }
  }
  const auto busy = busy_pixels_.report(seconds_between(first_t_us_, last_t_us_), events_);
  if (busy) {
    char label[32];
    std::snprintf(label, sizeof label, "pixels >= %.0f Hz", BusyPixels::kMinRateHz);
    std::fprintf(out, "  %-20s%s\n", label, busy->text.c_str());
    if (busy->pixels > 0) std::fprintf(out, "%22s(%s)\n", "", BusyPixels::kMeaning);
  }
}

}  // namespace evlife::cli
