// The evaluation of `evlife eval` (evaluation.h), moved out of the command line.
#include "evlife/render/evaluation.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>
#include "evlife/io/event_reader.h"
#include "evlife/io/output_path.h"
#include "evlife/render/active_event_set.h"
#include "evlife/render/augmented_source.h"
#include "evlife/render/fixed_window_map.h"
#include "evlife/render/frame_clock.h"
#include "evlife/render/frame_composer.h"
#include "evlife/render/frame_painter.h"
#include "evlife/render/image_quality.h"
#include "evlife/render/media.h"
#include "evlife/render/plot.h"
#include "evlife/render/render_cursor.h"
#include "evlife/render/sharpness.h"

namespace evlife::render::eval {
namespace {

namespace fs = std::filesystem;
using OutputError = EvaluationOutputError;

// Passes events through while measuring them.
class TapSource final : public render::AugmentedSource {
 public:
  TapSource(render::AugmentedSource& inner, RunResult& result, const std::atomic<bool>* stop)
      : inner_(inner), result_(result), stop_(stop) {}
  std::size_t read(std::span<AugmentedEvent> out) override {
    if (stop_ != nullptr && stop_->load(std::memory_order_relaxed)) throw EvaluationStopped{};
    const std::size_t n = inner_.read(out);
    result_.add(out.first(n));
    return n;
  }
  SensorSize sensor() const override { return inner_.sensor(); }
  std::string description() const override { return inner_.description(); }
  const LifetimeStats* estimator_stats() const override { return inner_.estimator_stats(); }
  const io::EventReader* event_reader() const override { return inner_.event_reader(); }

 private:
  render::AugmentedSource& inner_;
  RunResult& result_;
  const std::atomic<bool>* stop_;
};

// run_with_sharpness's sampling: the sharpness at every instant, the compare
// frame at its instant, then the rest of the recording read.
template <class DrawCompareFrame>
void sample_sharpness(render::RenderCursor& cursor, const render::ActiveEventSet& set,
                      const render::FixedWindowMap& window, const EvaluationOptions& args, std::int64_t first_t_us,
                      const DrawCompareFrame& draw_compare_frame, SharpnessResult& sharp) {
  std::array<cv::Mat, kMethods> masks;
  const std::int64_t step = args.sample_every_us;
  for (std::int64_t rel = step;;) {
    // The loop reads no event itself: a pause of an hour is 72,000 instants.
    if (args.stop != nullptr && args.stop->load(std::memory_order_relaxed)) throw EvaluationStopped{};
    std::int64_t t = 0;
    if (__builtin_add_overflow(first_t_us, rel, &t)) break;  // past the clock's end
    if (sharp.compare_frame.empty() && args.frame_at_us <= rel) draw_compare_frame();
    cursor.advance_to(t);
    if (cursor.exhausted() && t > cursor.last_fed_t_us()) break;
    for (std::size_t m = 0; m < kLifetimeMethod; ++m) render::window_mask(window, t, kWindowLengthsUs[m], masks[m]);
    render::active_mask(set, t, masks[kLifetimeMethod]);
    if (std::all_of(masks.begin(), masks.begin() + kLifetimeMethod, [](const cv::Mat& m) { return cv::countNonZero(m) == 0; })) {
      // A pause: no event within the longest window, so no fixed window draws
      // a pixel and completeness has no reference; nor does one at any
      // instant before the next event read (a window only loses events while
      // none comes). Those instants are counted, not sampled (an event of a
      // corrupt lifetime, active for ever, kept an hour's pause sampled).
      const auto next = cursor.next_t_us();
      const auto step_u = static_cast<std::uint64_t>(step), rel_u = static_cast<std::uint64_t>(rel);
      const std::uint64_t last_empty_rel = next && *next > t ? (span_us(first_t_us, *next) - 1) / step_u * step_u : rel_u;
      sharp.empty_instants += (last_empty_rel - rel_u) / step_u + 1;
      if (last_empty_rel > static_cast<std::uint64_t>(INT64_MAX)) break;
      rel = static_cast<std::int64_t>(last_empty_rel);
    } else {
      SharpnessSample s;
      s.t_s = static_cast<double>(rel) * 1e-6;
      const auto quality = render::compare_images(masks, kLifetimeMethod);
      std::copy(quality.begin(), quality.end(), s.methods.begin());
      for (std::size_t m = 0; m < kMethods; ++m) sharp.pooled[m] += s.methods[m];
      sharp.samples.push_back(s);
    }
    if (__builtin_add_overflow(rel, step, &rel)) break;
  }
  if (sharp.compare_frame.empty()) draw_compare_frame();  // --frame-at after the last sample
  cursor.advance_to(INT64_MAX);  // the statistics cover the whole recording
}

// The measuring pass with rendering: sharpness at every sample instant and the compare frame.
void run_with_sharpness(render::AugmentedSource& source, RunResult& result, const EvaluationOptions& args,
                        SharpnessResult& sharp) {
  TapSource tap(source, result, args.stop);
  const SensorSize sensor = source.sensor();
  render::ActiveEventSet set(sensor, true);
  render::FixedWindowMap window(sensor);
  render::RenderCursor cursor(tap, set, &window);
  const auto first = cursor.first_t_us();
  if (!first) return;
  render::FrameStyle style;
  style.scale = FrameStyle::scale_to_fit(sensor.width, sensor.height, 384);
  render::FrameComposer composer(render::parse_view_mode("compare"), style, "compare");
  const auto compose_at = [&](std::int64_t t) {
    composer.compose(set, window, t, render::clock_span_us(*first, t)).copyTo(sharp.compare_frame);
    sharp.compare_t_s = seconds_between(*first, t);
  };
  // At --frame-at itself (not the sample after it), or at the last event when
  // the recording ends before it. The cursor is never past that instant here.
  const auto draw_compare_frame = [&] {
    std::int64_t t = render::clock_add_us(*first, args.frame_at_us);
    cursor.advance_to(t);
    if (cursor.exhausted() && t > cursor.last_fed_t_us()) t = cursor.last_fed_t_us();
    compose_at(t);
  };
  try {
    sample_sharpness(cursor, set, window, args, *first, draw_compare_frame, sharp);
  } catch (const io::ReadError&) {
    // A fault of the input: the compare frame of the events before it (at
    // --frame-at, or at the last of them; reading on would meet the fault
    // again), and their counts, then the fault.
    if (sharp.compare_frame.empty() && cursor.events_fed() > 0)
      compose_at(std::min(render::clock_add_us(*first, args.frame_at_us), cursor.last_fed_t_us()));
    sharp.frame_events = set.stats();
    throw;
  }
  sharp.frame_events = set.stats();
}

void run_plain(render::AugmentedSource& source, RunResult& result, const std::atomic<bool>* stop) {
  TapSource tap(source, result, stop);
  std::vector<AugmentedEvent> buf(1 << 14);
  while (tap.read(buf) > 0) {
  }
}


// The report's files, each name written once: the writers, summary.html's
// links and report_file_names() (the refusal of an input among them) take
// them from here. Stems are written as STEM.png and STEM.csv.
namespace report {
constexpr const char* kLifetimeHistogram = "lifetime_histogram";
constexpr const char* kVelocityHistogram = "velocity_histogram";
constexpr const char* kVelocityComponents = "velocity_components";
constexpr const char* kPredictionErrorCdf = "prediction_error_cdf";
constexpr const char* kSharpness = "sharpness";
constexpr const char* kSharpnessSummary = "sharpness_summary.csv";
constexpr const char* kCompareFrame = "compare_frame.png";
constexpr const char* kRuns = "runs.csv";
constexpr const char* kSummary = "summary.html";
}  // namespace report

// The report's folder: each file named in it is checked against the input
// (`eval evo/runs.csv -o evo` wrote its runs.csv over the recording).
class ReportDir {
 public:
  explicit ReportDir(const EvaluationOptions& args) : dir_(args.output), input_(args.input) {}
  fs::path operator/(const std::string& name) const {
    fs::path path = dir_ / name;
    if (const auto refusal = io::output_overwrites_input(input_, path.string())) throw OutputError(*refusal);
    return path;
  }

 private:
  fs::path dir_;
  std::string input_;
};

void write_png(const fs::path& path, const cv::Mat& img) {
  try {
    render::write_image(path.string(), img);
  } catch (const std::runtime_error& e) {
    throw OutputError(e.what());
  }
}

// A text output whose write errors (a full disk shows at the flush) are an
// OutputError at close(), not a file left empty behind exit 0.
class TextFile {
 public:
  explicit TextFile(fs::path path) : path_(std::move(path)), out_(path_) {
    if (!out_) throw OutputError("cannot write " + path_.string());
  }
  template <class T>
  TextFile& operator<<(const T& value) {
    out_ << value;
    return *this;
  }
  void close() {
    out_.close();
    if (out_.fail()) throw OutputError("cannot write " + path_.string() + " (disk full?)");
  }

 private:
  fs::path path_;
  std::ofstream out_;
};

double ceil_nice(double v) {
  if (!(v > 0.0) || !std::isfinite(v)) return 1.0;
  const double mag = std::pow(10.0, std::floor(std::log10(v)));
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
    if (m * mag >= v) return m * mag;
  return 10.0 * mag;
}

const RunResult* find_run(const std::vector<RunResult>& runs, int n, bool reg) {
  for (const auto& r : runs)
    if (!r.from_file && r.window_size == n && r.regularization == reg) return &r;
  return nullptr;
}

// Histogram series of the given runs, bins in `scale` units, up to x_max (in those units).
void histogram_outputs(const ReportDir& dir, const std::string& stem, const std::string& title,
                       const std::string& x_label, double scale,
                       const std::vector<std::pair<const RunResult*, const render::Histogram*>>& series,
                       double x_max) {
  std::vector<render::PlotSeries> plot;
  int k = 0;
  for (const auto& [run, h] : series) {
    render::PlotSeries s;
    s.label = run->label;
    s.color = render::series_color(run->regularization ? 1 : 0);
    if (series.size() == 1 || run->from_file) s.color = render::series_color(k);
    s.style = render::PlotSeries::Style::step;
    // Earlier series wider, so identical curves drawn on top stay visible.
    s.thickness = k == 0 && series.size() > 1 ? 4 : 2;
    for (std::size_t b = 0; b < h->bins(); ++b) {
      if (h->bin_start(b) / scale > x_max) break;
      s.x.push_back(h->bin_start(b) / scale);
      s.y.push_back(static_cast<double>(h->count(b)));
    }
    plot.push_back(std::move(s));
    ++k;
  }
  render::PlotOptions o;
  o.title = title;
  o.x_label = x_label;
  o.y_label = "events per bin";
  const double lo = series.front().second->lo() / scale;
  o.x_min = std::max(lo, series.front().second->lo() < 0 ? -x_max : 0.0);
  o.x_max = x_max;
  write_png(dir / (stem + ".png"), render::draw_plot(o, plot));

  TextFile csv(dir / (stem + ".csv"));
  csv << "bin_start,bin_end";
  for (const auto& [run, h] : series) csv << ",\"" << run->label << "\"";
  csv << "\n";
  const auto* h0 = series.front().second;
  for (std::size_t b = 0; b < h0->bins(); ++b) {
    csv << h0->bin_start(b) / scale << "," << h0->bin_start(b + 1) / scale;
    for (const auto& p : series) csv << "," << p.second->count(b);
    csv << "\n";
  }
  csv << "# values below the first bin / above the last:";
  for (const auto& p : series) csv << " " << p.second->below() << "/" << p.second->above();
  csv << "\n";
  csv.close();
}

// NaN (a completeness without reference edges, its score): "n/a", not "nan %".
std::string pct(double share) {
  if (std::isnan(share)) return "n/a";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f %%", 100.0 * share);
  return buf;
}

std::string fmt(const char* format, double v) {
  if (std::isnan(v)) return "n/a";
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

// A CSV field: empty for NaN (no figure), as pandas and spreadsheets read a missing value.
std::string csv_field(double v) {
  if (std::isnan(v)) return {};
  std::ostringstream text;
  text << v;
  return text.str();
}

// Why the sharpness has no instant (its table would be the empty pool's defaults).
std::string no_sharpness_instant(const EvaluationOptions& args, const RunResult& r, const SharpnessResult& sharp) {
  if (sharp.empty_instants > 0) {
    return "no instant sampled: no fixed window drew a pixel at any of the " + std::to_string(sharp.empty_instants) +
           " instants";
  }
  if (r.events == 0) return "no instant sampled: no event to sample";
  return fmt("no instant sampled: the recording (%.6f s) is shorter than", seconds_between(r.first_t_us, r.last_t_us)) +
         fmt(" --sample-every (%.6f s)", static_cast<double>(args.sample_every_us) * 1e-6);
}

// ", and N instants of pauses (no fixed window draws a pixel), left out" (empty without them).
std::string empty_instants_note(const SharpnessResult& sharp) {
  if (sharp.empty_instants == 0) return {};
  return ", and " + std::to_string(sharp.empty_instants) +
         " instants of pauses (no fixed window draws a pixel), left out";
}

void write_histograms([[maybe_unused]] const EvaluationOptions& args, [[maybe_unused]] const std::string& description,
    [[maybe_unused]] SensorSize sensor, [[maybe_unused]] const std::vector<RunResult>& runs,
    [[maybe_unused]] const RunResult& primary, [[maybe_unused]] const SharpnessResult& sharp) {
  const ReportDir dir(args);
  // Fig. 10: lifetime histogram for N = 5 with and without regularization.
  std::vector<std::pair<const RunResult*, const render::Histogram*>> lifetime_series, speed_series;
  const RunResult* n5r = find_run(runs, 5, true);
  const RunResult* n5 = find_run(runs, 5, false);
  if (n5 && n5r) {
    lifetime_series = {{n5, &n5->lifetime_us}, {n5r, &n5r->lifetime_us}};
    speed_series = {{n5, &n5->speed_px_s}, {n5r, &n5r->speed_px_s}};
  } else {
    lifetime_series = {{&primary, &primary.lifetime_us}};
    speed_series = {{&primary, &primary.speed_px_s}};
  }
  double lifetime_max_ms = 0.0, speed_max = 0.0;
  // Show the bulk (a long tail of slow background edges would flatten the peaks).
  for (const auto& p : lifetime_series) lifetime_max_ms = std::max(lifetime_max_ms, 1.5 * p.second->quantile(0.95) / 1000.0);
  for (const auto& p : speed_series) speed_max = std::max(speed_max, 1.5 * p.second->quantile(0.95));
  histogram_outputs(dir, report::kLifetimeHistogram, "Lifetime histogram (0.2 ms bins, noise excluded)",
                    "lifetime [ms]", 1000.0, lifetime_series, ceil_nice(lifetime_max_ms));
  histogram_outputs(dir, report::kVelocityHistogram, "Speed of non-noise events", "speed |v| [px/s]", 1.0,
                    speed_series, ceil_nice(speed_max));
  {
    const RunResult& r = primary;
    const double vmax = ceil_nice(std::max({std::fabs(r.vx_px_s.quantile(0.005)), std::fabs(r.vx_px_s.quantile(0.995)),
                                            std::fabs(r.vy_px_s.quantile(0.005)), std::fabs(r.vy_px_s.quantile(0.995))}));
    RunResult vx_run = RunResult{};
    vx_run.label = "vx (" + r.label + ")";
    RunResult vy_run = RunResult{};
    vy_run.label = "vy (" + r.label + ")";
    vy_run.from_file = vx_run.from_file = true;  // colour by order
    histogram_outputs(dir, report::kVelocityComponents, "Velocity components of non-noise events", "velocity [px/s]",
                      1.0, {{&vx_run, &r.vx_px_s}, {&vy_run, &r.vy_px_s}}, vmax);
  }

}

void write_prediction_error_cdf([[maybe_unused]] const EvaluationOptions& args, [[maybe_unused]] const std::string& description,
    [[maybe_unused]] SensorSize sensor, [[maybe_unused]] const std::vector<RunResult>& runs,
    [[maybe_unused]] const RunResult& primary, [[maybe_unused]] const SharpnessResult& sharp) {
  const ReportDir dir(args);
  // Fig. 9: CDF of |prediction error|.
  {
    std::vector<render::PlotSeries> plot;
    const double x_max_ms = 50.0;
    for (const RunResult& r : runs) {
      render::PlotSeries s;
      s.label = r.label;
      s.color = render::series_color(r.from_file ? 0 : (r.window_size - 3) / 2);
      s.dashed = !r.regularization && !r.from_file;
      if (r.predictions == 0) {  // in the legend, said, not left out of the comparison
        s.label += " (no prediction)";
        plot.push_back(std::move(s));
        continue;
      }
      s.x.push_back(0.0);
      s.y.push_back(0.0);  // no prediction has a negative error
      for (std::size_t b = 0; b < r.abs_error_us.bins(); ++b) {
        const double x = r.abs_error_us.bin_start(b + 1) / 1000.0;
        if (x > x_max_ms) break;
        s.x.push_back(x);
        s.y.push_back(r.abs_error_us.cdf_at_bin_end(b));
      }
      plot.push_back(std::move(s));
    }
    render::PlotOptions o;
    o.title = "Cumulative distribution of |prediction error| (solid: regularized, dashed: not)";
    o.x_label = "absolute prediction error [ms]";
    o.y_label = "share of predictions";
    o.x_min = 0.0;
    o.x_max = x_max_ms;
    o.y_min = 0.0;
    o.y_max = 1.0;
    o.legend_bottom = true;
    write_png(dir / (std::string(report::kPredictionErrorCdf) + ".png"), render::draw_plot(o, plot));
    TextFile csv(dir / (std::string(report::kPredictionErrorCdf) + ".csv"));
    csv << "abs_error_ms";
    for (const RunResult& r : runs) csv << ",\"" << r.label << "\"";
    csv << "\n";
    for (std::size_t b = 0; b < 5000; ++b) {
      csv << static_cast<double>(b + 1) * 0.1;
      for (const RunResult& r : runs) {  // a run without predictions has no distribution: empty fields
        csv << ",";
        if (r.predictions > 0) csv << r.abs_error_us.cdf_at_bin_end(b);
      }
      csv << "\n";
    }
    csv.close();
  }

}

void write_sharpness([[maybe_unused]] const EvaluationOptions& args, [[maybe_unused]] const std::string& description,
    [[maybe_unused]] SensorSize sensor, [[maybe_unused]] const std::vector<RunResult>& runs,
    [[maybe_unused]] const RunResult& primary, [[maybe_unused]] const SharpnessResult& sharp) {
  const ReportDir dir(args);
  // Sharpness and completeness.
  {
    std::vector<render::PlotSeries> plot(kMethods);
    for (std::size_t m = 0; m < kMethods; ++m) {
      plot[m].label = kMethodNames[m];
      plot[m].color = render::series_color(static_cast<int>(m == kLifetimeMethod ? 1 : (m == 0 ? 2 : m + 2)));
    }
    TextFile csv(dir / (std::string(report::kSharpness) + ".csv"));
    csv << "t_s,method,active_pixels,edge_pixels,thin_edge_pixels,thin_edge_share,mean_edge_thickness_px,"
           "completeness,score\n";
    for (const auto& s : sharp.samples) {
      for (std::size_t m = 0; m < kMethods; ++m) {
        const MethodQuality& q = s.methods[m];
        plot[m].x.push_back(s.t_s);
        plot[m].y.push_back(q.score());
        csv << s.t_s << "," << kMethodNames[m] << "," << q.sharpness.active_pixels << "," << q.sharpness.edge_pixels
            << "," << q.sharpness.thin_edge_pixels << "," << q.sharpness.thin_edge_share() << ","
            << csv_field(q.sharpness.mean_edge_thickness_px) << "," << csv_field(q.completeness.share()) << ","
            << csv_field(q.score()) << "\n";
      }
    }
    csv.close();
    render::PlotOptions o;
    o.title = "Complete and sharp: completeness x thin-edge share (higher = better)";
    o.x_label = "time [s]";
    o.y_label = "completeness x thin-edge share";
    o.y_min = 0.0;
    o.y_max = 1.0;
    o.legend_bottom = true;
    write_png(dir / (std::string(report::kSharpness) + ".png"), render::draw_plot(o, plot));
    TextFile sum(dir / report::kSharpnessSummary);
    sum << "method,samples,active_pixels_per_sample,edge_pixels_per_sample,thin_edge_share,mean_edge_thickness_px,"
           "completeness,score\n";
    const double n = static_cast<double>(std::max<std::size_t>(sharp.samples.size(), 1));
    for (std::size_t m = 0; m < kMethods; ++m) {
      const MethodQuality& q = sharp.pooled[m];
      sum << kMethodNames[m] << "," << sharp.samples.size();
      if (sharp.samples.empty()) {  // no instant: no figure (not the empty pool's defaults)
        sum << ",,,,,,\n";
        continue;
      }
      sum << "," << static_cast<double>(q.sharpness.active_pixels) / n
          << "," << static_cast<double>(q.sharpness.edge_pixels) / n << "," << q.sharpness.thin_edge_share() << ","
          << csv_field(q.sharpness.mean_edge_thickness_px) << "," << csv_field(q.completeness.share()) << ","
          << csv_field(q.score()) << "\n";
    }
    sum.close();
  }
  const fs::path compare_frame = dir / report::kCompareFrame;
  if (!sharp.compare_frame.empty()) {
    write_png(compare_frame, sharp.compare_frame);
  } else {  // no event to draw: an earlier run's frame in a reused folder is not this run's
    std::error_code ec;
    fs::remove(compare_frame, ec);
    if (ec) throw OutputError("cannot remove an earlier run's " + compare_frame.string() + ": " + ec.message());
  }

}

void write_runs_csv([[maybe_unused]] const EvaluationOptions& args, [[maybe_unused]] const std::string& description,
    [[maybe_unused]] SensorSize sensor, [[maybe_unused]] const std::vector<RunResult>& runs,
    [[maybe_unused]] const RunResult& primary, [[maybe_unused]] const SharpnessResult& sharp) {
  const ReportDir dir(args);
  // runs.csv
  {
    TextFile csv(dir / report::kRuns);
    csv << "run,window_size,regularization,events,noise,noise_share,predictions,median_lifetime_ms,"
           "median_abs_error_ms,share_abs_error_below_10ms,wall_s,share_with_lifetime,share_with_prediction,"
           "median_abs_error_over_lifetime\n";
    for (const auto& r : runs) {
      csv << "\"" << r.label << "\",";
      if (r.from_file)  // the file's lifetimes: it does not say which estimator options made them
        csv << ",";
      else
        csv << r.window_size << "," << (r.regularization ? 1 : 0);
      csv << "," << r.events
          << "," << r.noise << "," << (r.events ? static_cast<double>(r.noise) / static_cast<double>(r.events) : 0.0)
          << "," << r.predictions << "," << r.median_lifetime_ms() << ","
          << r.median_abs_error_ms() << "," << r.share_abs_error_below_10ms() << "," << r.wall_s
          << "," << r.share_with_lifetime() << "," << r.share_with_prediction() << ","
          << r.median_error_over_lifetime() << "\n";
    }
    csv.close();
  }

}

void write_summary_html([[maybe_unused]] const EvaluationOptions& args, [[maybe_unused]] const std::string& description,
    [[maybe_unused]] SensorSize sensor, [[maybe_unused]] const std::vector<RunResult>& runs,
    [[maybe_unused]] const RunResult& primary, [[maybe_unused]] const SharpnessResult& sharp) {
  const ReportDir dir(args);
  // summary.html
  TextFile html(dir / report::kSummary);
  html << "<!doctype html><html><head><meta charset=\"utf-8\"><title>evlife eval: " << description
       << "</title><style>body{font-family:sans-serif;max-width:1600px;margin:1em auto}"
          "table{border-collapse:collapse}td,th{border:1px solid #bbb;padding:3px 8px;text-align:right}"
          "th{background:#eee}img{max-width:49%;margin:2px}</style></head><body>\n";
  html << "<h1>evlife eval</h1><p>Input: <b>" << description << "</b>, sensor " << sensor.width << "&times;"
       << sensor.height << ". Lifetime estimation after Mueggler et al., ICRA 2015.</p>\n";
  html << "<h2>Estimator runs</h2><table><tr><th>run</th><th>events</th><th>with a lifetime</th>"
          "<th>with a prediction</th><th>median lifetime</th><th>median |pred. error|</th>"
          "<th>median |pred. error| / lifetime</th><th>|pred. error| &lt; 10 ms</th><th>wall</th></tr>\n";
  for (const auto& r : runs) {
    html << "<tr><td style=\"text-align:left\">" << r.label << "</td><td>" << r.events << "</td><td>"
         << pct(r.share_with_lifetime()) << "</td><td>" << pct(r.share_with_prediction()) << "</td><td>"
         << fmt("%.2f ms", r.median_lifetime_ms()) << "</td><td>"
         << fmt("%.2f ms", r.median_abs_error_ms()) << "</td><td>"
         << fmt("%.3f", r.median_error_over_lifetime()) << "</td><td>"
         << pct(r.share_abs_error_below_10ms()) << "</td><td>" << fmt("%.2f s", r.wall_s) << "</td></tr>\n";
  }
  html << "</table>\n<h2>Sharpness (" << sharp.samples.size() << " instants, every "
       << static_cast<double>(args.sample_every_us) / 1000.0 << " ms" << empty_instants_note(sharp) << "; "
       << primary.label << ")</h2>\n"
       << "<table><tr><th>method</th><th>drawn pixels / image</th><th>edge pixels / image</th>"
          "<th>thin-edge share</th><th>mean edge thickness</th><th>completeness</th>"
          "<th>completeness &times; thin-edge share</th></tr>\n";
  if (sharp.samples.empty()) {
    html << "<tr><td colspan=\"7\">" << no_sharpness_instant(args, primary, sharp) << "</td></tr>\n";
  } else {
    const double n = static_cast<double>(sharp.samples.size());
    for (std::size_t m = 0; m < kMethods; ++m) {
      const MethodQuality& q = sharp.pooled[m];
      html << "<tr><td style=\"text-align:left\">" << kMethodNames[m] << "</td><td>"
           << fmt("%.0f", static_cast<double>(q.sharpness.active_pixels) / n) << "</td><td>"
           << fmt("%.0f", static_cast<double>(q.sharpness.edge_pixels) / n) << "</td><td>"
           << pct(q.sharpness.thin_edge_share()) << "</td><td>" << fmt("%.2f px", q.sharpness.mean_edge_thickness_px)
           << "</td><td>" << pct(q.completeness.share()) << "</td><td>" << fmt("%.3f", q.score()) << "</td></tr>\n";
    }
  }
  html << "</table><p>A pixel lies on an edge when a run of &ge; 3 drawn pixels passes through it; on a thin edge"
          " when, in addition, its horizontal or vertical run is &le; 2 px. Thin-edge share = thin-edge pixels /"
          " drawn pixels. Completeness = share of the edge pixels of the best fixed window at that instant (the one"
          " with the most thin-edge pixels) that the image draws within 1 px.</p>\n";
  if (render::ignored_events(sharp.frame_events) > 0)
    html << "<p>Not in the frames (the runs count them): " << render::ignored_events_text(sharp.frame_events) << ".</p>\n";
  if (!sharp.compare_frame.empty()) {
    html << "<h2>Compare frame (t = " << fmt("%.3f", sharp.compare_t_s)
         << " s)</h2><img style=\"max-width:100%\" src=\"" << report::kCompareFrame << "\">\n";
  }
  html
       << "<h2>Figures</h2>";
  for (const char* stem : {report::kLifetimeHistogram, report::kPredictionErrorCdf, report::kVelocityHistogram,
                           report::kVelocityComponents, report::kSharpness})
    html << "<img src=\"" << stem << ".png\">";
  html << "\n"
       << "<p>The numbers behind every figure are in the CSV file of the same name.</p></body></html>\n";
  html.close();
}
void write_outputs(const EvaluationOptions& args, const std::string& description, SensorSize sensor,
                   const std::vector<RunResult>& runs, const RunResult& primary,
                   const SharpnessResult& sharp) {
  write_histograms(args, description, sensor, runs, primary, sharp);
  write_prediction_error_cdf(args, description, sensor, runs, primary, sharp);
  write_sharpness(args, description, sensor, runs, primary, sharp);
  write_runs_csv(args, description, sensor, runs, primary, sharp);
  write_summary_html(args, description, sensor, runs, primary, sharp);
}

}  // namespace

std::string comparison_runs_refusal(const LifetimeOptions& configured) {
  std::string sizes;  // "3, 5 and 7"
  for (std::size_t i = 0; i < std::size(kEstimatorWindowSizes); ++i) {
    sizes += (i == 0 ? "" : i + 1 == std::size(kEstimatorWindowSizes) ? " and " : ", ") +
             std::to_string(kEstimatorWindowSizes[i]);
  }
  for (const int n : kEstimatorWindowSizes) {
    LifetimeOptions o = configured;
    o.window_size = n;
    if (const std::string err = validate_lifetime_options(o); !err.empty()) {
      return "eval runs N = " + sizes + " with the rest of the configuration; with window_size " + std::to_string(n) +
             ", estimator." + err;
    }
  }
  return {};
}

Evaluation evaluate(const EvaluationOptions& args) {
  Evaluation ev;
  auto& runs = ev.runs;
  auto& sharp = ev.sharp;
  auto& description = ev.description;
  auto& sensor = ev.sensor;
  auto& primary_index = ev.primary_index;
  {
    // The configured run first: it also measures sharpness.
    auto run_once = [&](int n, bool reg, bool primary) {
      LifetimeOptions o = args.estimator;
      o.window_size = n;
      o.regularization = reg;
      const auto t0 = std::chrono::steady_clock::now();
      auto source = render::open_augmented_source(args.input, o, args.sensor, args.input_options, args.stop);
      if (args.stop != nullptr && args.stop->load(std::memory_order_relaxed)) throw EvaluationStopped{};  // in the scan
      RunResult r;
      r.from_file = source->estimator_stats() == nullptr;
      r.window_size = r.from_file ? 0 : n;
      r.regularization = r.from_file ? false : reg;
      r.label = r.from_file ? "lifetimes from the file"
                            : "N=" + std::to_string(n) + (reg ? ", regularized" : ", not regularized");
      if (!args.quiet) std::fprintf(stderr, "evlife eval: %s ...\n", r.label.c_str());
      try {
        if (primary) {
          description = source->description();
          sensor = source->sensor();
          // Never a silent drop: records of the file that are no events (stated when read through).
          const auto note_skipped = [&] {
            if (const io::EventReader* reader = source->event_reader(); reader && reader->skipped_record_count() > 0)
              description += "; skipped records " + io::skipped_records_text(*reader);
          };
          try {
            run_with_sharpness(*source, r, args, sharp);
          } catch (const io::ReadError&) {
            note_skipped();
            throw;
          }
          note_skipped();
        } else {
          run_plain(*source, r, args.stop);
        }
      } catch (const io::ReadError& e) {
        // The events before a fault are evaluated (every run stops at the
        // same one); with none there is nothing to evaluate.
        if (r.events == 0) throw;
        if (!ev.input_fault) {
          ev.input_fault.emplace(e);
          description += " (stopped by an input fault: the events before it are evaluated)";
        }
      }
      r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      runs.push_back(std::move(r));
    };
    run_once(args.estimator.window_size, args.estimator.regularization, true);
    if (!runs.front().from_file) {
      for (const int n : kEstimatorWindowSizes)
        for (bool reg : {false, true})
          if (n != args.estimator.window_size || reg != args.estimator.regularization) run_once(n, reg, false);
      // Order the table by N, then regularization.
      std::stable_sort(runs.begin(), runs.end(), [](const RunResult& a, const RunResult& b) {
        return a.window_size != b.window_size ? a.window_size < b.window_size : a.regularization < b.regularization;
      });
      for (std::size_t i = 0; i < runs.size(); ++i)
        if (runs[i].window_size == args.estimator.window_size &&
            runs[i].regularization == args.estimator.regularization)
          primary_index = i;
    }
  }
  return ev;
}

void print_evaluation_summary(std::FILE* out, const EvaluationOptions& args, const Evaluation& ev) {
  const auto& runs = ev.runs;
  const auto& sharp = ev.sharp;
  const auto& description = ev.description;
  std::fprintf(out, "evlife eval: %s -> %s/%s\n", description.c_str(), args.output.c_str(), report::kSummary);
  if (!runs.empty()) {
    const RunResult& r = runs[ev.primary_index];
    if (r.events == 0)  // no first or last time to give (it said "t = 0 .. 0 us (0.000000 s long)")
      std::fprintf(out, "  time range                 no event\n");
    else
      std::fprintf(out, "  time range                 t = %lld .. %lld us (%.6f s long)\n",
                   static_cast<long long>(r.first_t_us), static_cast<long long>(r.last_t_us),
                   seconds_between(r.first_t_us, r.last_t_us));
    // (Not for the default instant: a recording shorter than it is no mistake of the user's.)
    if (args.frame_at_given && r.events > 0 && args.frame_at_us > seconds_between(r.first_t_us, r.last_t_us) * 1e6)
      std::fprintf(stderr, "evlife eval: warning: --frame-at %.6f s lies after the last event; the "
                   "compare frame is drawn at the last event (%.6f s)\n", static_cast<double>(args.frame_at_us) * 1e-6,
                   seconds_between(r.first_t_us, r.last_t_us));
  }
  for (const auto& r : runs) {
    std::fprintf(out,
                 "  %-26s %9llu events, with a lifetime %5.1f %%, with a prediction %5.1f %%, median lifetime "
                 "%9s, |pred. err| < 10 ms: %7s, median |pred. err|/lifetime %s\n",
                 r.label.c_str(), static_cast<unsigned long long>(r.events), 100.0 * r.share_with_lifetime(),
                 100.0 * r.share_with_prediction(), fmt("%.2f ms", r.median_lifetime_ms()).c_str(),
                 pct(r.share_abs_error_below_10ms()).c_str(), fmt("%.3f", r.median_error_over_lifetime()).c_str());
  }
  // Never a silent drop: the frames leave these out (a --sensor smaller than the events', a corrupt time).
  if (render::ignored_events(sharp.frame_events) > 0)
    std::fprintf(out, "  not in the frames          %s (the runs above count them)\n",
                 render::ignored_events_text(sharp.frame_events).c_str());
  if (sharp.samples.empty()) {
    if (!runs.empty()) std::fprintf(out, "  sharpness: %s\n", no_sharpness_instant(args, runs[ev.primary_index], sharp).c_str());
    return;
  }
  std::fprintf(out, "  over %zu instants%s: thin-edge share, mean edge thickness, completeness, score (product):\n",
               sharp.samples.size(), empty_instants_note(sharp).c_str());
  for (std::size_t m = 0; m < kMethods; ++m) {
    const MethodQuality& q = sharp.pooled[m];
    std::fprintf(out, "    %-20s %5.1f %%  %8s  %7s  %s\n", kMethodNames[m],
                 100.0 * q.sharpness.thin_edge_share(), fmt("%.2f px", q.sharpness.mean_edge_thickness_px).c_str(),
                 pct(q.completeness.share()).c_str(), fmt("%.3f", q.score()).c_str());
  }
}

std::vector<std::string> report_file_names() {
  std::vector<std::string> names{report::kSharpnessSummary, report::kCompareFrame, report::kRuns, report::kSummary};
  for (const char* stem : {report::kLifetimeHistogram, report::kVelocityHistogram, report::kVelocityComponents,
                           report::kPredictionErrorCdf, report::kSharpness}) {
    for (const char* extension : {".png", ".csv"}) names.push_back(stem + std::string(extension));
  }
  return names;
}

void write_evaluation(const EvaluationOptions& options, const Evaluation& ev) {
  write_outputs(options, ev.description, ev.sensor, ev.runs, ev.runs[ev.primary_index], ev.sharp);
}

}  // namespace evlife::render::eval
