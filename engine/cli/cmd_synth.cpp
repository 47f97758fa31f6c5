// `evlife synth -o FILE`: writes a synthetic scene with known ground truth
// (moving edges, a rotating bar that speeds up, jitter, background noise) as
// an event recording — the bundled sample of the README and a test input for
// anyone. Streams slice by slice (the memory of one slice, which grows with the
// background rate and the sensor: refused when it cannot fit), deterministic per seed.
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "arg_parser.h"
#include "command_start.h"
#include "command.h"
#include "evlife/io/event_writer.h"
#include "evlife/io/output_path.h"
#include "evlife/io/synthetic_scene.h"
#include "evlife/io/textured_scene.h"
#include "evlife/io/write_error.h"
#include "exit_code.h"
#include "memory_check.h"
#include "stop_signals.h"

namespace evlife::cli::synth_command {
namespace {

constexpr std::size_t kBatchEvents = 1 << 16;

constexpr OptionSpec kOptions[] = {
    {"output", 'o', true, false},     {"scene", 0, true, false},  {"sensor", 0, true, false},
    {"duration", 0, true, false},     {"seed", 0, true, false},   {"noise-rate", 0, true, false},
    {"jitter-us", 0, true, false},    {"truth", 0, true, false},  {"quiet", 'q', false, false},
    {"help", 'h', false, false},      {"pixel", 0, true, false},  {"contrast", 0, true, false},
    {"threshold", 0, true, false},    {"threshold-sigma", 0, true, false},
    {"edge-blur-px", 0, true, false}, {"latency-us", 0, true, false},
    {"latency-jitter-us", 0, true, false}, {"refractory-us", 0, true, false},
    {"hot-pixels", 0, true, false},   {"hot-rate", 0, true, false},
    {"cutoff-hz", 0, true, false},    {"timestamp-quantum-us", 0, true, false},
};

void print_help(std::FILE* out) {
  std::fprintf(out,
      "evlife synth — write a synthetic event recording with known ground truth\n"
      "\n"
      "Usage: evlife synth -o FILE [--scene edges|bar|mixed|large|edges-bar|textured] [--sensor WxH]\n"
      "                    [--duration T] [--seed N] [--noise-rate R] [--jitter-us J]\n"
      "                    [--pixel ideal|dvs|dvs-dim] [pixel options] [--truth TRUTH.csv] [--quiet]\n"
      "\n"
      "The scene: bright bars on a dark background. An event fires when an edge\n"
      "crosses a pixel centre: ON for the leading edge of a bar, OFF for the\n"
      "trailing one. Its true lifetime is 1 / the edge's normal speed.\n"
      "  edges  tiles of ~60 px, each a periodic pattern of straight bars with its own\n"
      "         direction (not axis-aligned) and lifetime (300 us .. 20 ms); pixels\n"
      "         are crossed again and again, as on a real camera.\n"
      "  bar    one bar turning about the sensor centre, speeding up from 150 to\n"
      "         1200 deg/s over the duration (the paper's quadrotor flip).\n"
      "  mixed  left half: a slow and a fast pattern; right half: the speeding bar.\n"
      "         (default; on 128x128 for 3 s: ~300 k events, the README's sample)\n"
      "  large  80 px tiles of patterns everywhere, all moving all the time: for\n"
      "         throughput tests on big sensors (1280x720 gives ~40 M events/s).\n"
      "  edges-bar  the tiles of 'edges' on the left two thirds, the speeding bar on\n"
      "         the right third (e.g. --sensor 346x260 --pixel dvs).\n"
      "  textured  not bars: a natural-looking texture ('dead leaves': overlapping\n"
      "         discs of random grey, sharp and blurred edges of every contrast,\n"
      "         orientation and curvature) in 60 px tiles, each translating 30 px\n"
      "         with its own direction and lifetime (500 us .. 20 ms) at the end of\n"
      "         the scene. Needs --pixel dvs or dvs-dim (default dvs): each pixel\n"
      "         samples the moving texture and fires at its thresholds. An event's\n"
      "         truth: 1 / the normal speed of the texture's iso-line through the\n"
      "         pixel. Generated in memory (~70 bytes per event).\n"
      "\n"
      "Pixels: 'ideal' (default) fires one event per edge crossing, as above. 'dvs'\n"
      "models a real DVS pixel in normal light: the edge is a log-intensity step\n"
      "(contrast) spread over a blurred profile; the pixel fires one event per\n"
      "threshold crossed (per-pixel mismatch), so an edge gives a burst of ~1-4\n"
      "events, stamped after a latency with jitter, each followed by a refractory\n"
      "period (within a burst: ON and OFF crossings, background and hot pixels are\n"
      "not held off by it); hot pixels fire on their own. 'dvs-dim': dim light (latency and\n"
      "jitter of hundreds of us, longer refractory period, more background noise).\n"
      "Every event of a burst carries the edge's truth.\n"
      "\n"
      "Options:\n"
      "  -o, --output FILE    .txt: RPG text, one event per line 't x y p' (t in\n"
      "                       seconds, 6 decimals; p 1 = ON, 0 = OFF; it cannot state the\n"
      "                       sensor: give readers --sensor); .h5: HDF5 x,y,t,p (p +1 =\n"
      "                       ON, -1 = OFF) with the sensor as attributes width and height.\n"
      "  --scene NAME         see above (default mixed).\n"
      "  --sensor WxH         sensor size in pixels (default 128x128, the DVS128).\n"
      "  --duration T         length of the scene: 1.5s, 500ms, or seconds (default 3).\n"
      "  --seed N             seed of jitter and noise (default 1); the same options\n"
      "                       give the same file byte for byte.\n"
      "  --noise-rate R       background noise, events per pixel per second, uniform\n"
      "                       over pixels and time, random polarity (default 1).\n"
      "  --jitter-us J        timestamp jitter: Gaussian sigma in microseconds,\n"
      "                       truncated at 4 sigma, applied before sorting (default 20;\n"
      "                       ideal pixels only: the pixel model has its latency jitter).\n"
      "  --pixel P            ideal | dvs | dvs-dim (default ideal); dvs sets the\n"
      "                       noise rate to 0.2, dvs-dim to 1 (--noise-rate overrides).\n"
      "  Pixel options (with --pixel dvs or dvs-dim; defaults: dvs | dvs-dim):\n"
      "  --contrast C         log-intensity step of an edge (0.5), varied +-40 %% per pattern.\n"
      "  --threshold T        ON/OFF threshold in log units (0.2).\n"
      "  --threshold-sigma S  per-pixel threshold mismatch, sigma in log units (0.03).\n"
      "  --edge-blur-px B     width of the edge profile in pixels (1.5).\n"
      "  --latency-us L       pixel latency: the centre of a Gaussian (80 | 500).\n"
      "  --latency-jitter-us J  its sigma per event (40 | 300), truncated at 0 and\n"
      "                       +-4 sigma: dvs-dim's events lag 531 us on average, sd 270.\n"
      "  --refractory-us R    refractory period (200 | 800).\n"
      "  --hot-pixels F       share of hot pixels, at least one when > 0 (0.0001).\n"
      "  --hot-rate H         events per second of a hot pixel (20).\n"
      "  --cutoff-hz F        photoreceptor bandwidth on an edge's bright side, 3 dB,\n"
      "                       Hz (0: unlimited). It falls with the light: ~300-3000\n"
      "                       Hz in office light, 10-300 Hz in dim light (v2e: 300\n"
      "                       at full white; its 'noisy' setting 30). The pixel then\n"
      "                       follows an ON edge with time constant 1 / (2 pi F), an\n"
      "                       OFF edge (to the dark side) e^contrast times slower.\n"
      "  --timestamp-quantum-us Q  stamps floored to multiples of Q us (0: 1 us): a\n"
      "                       frame-based emulator's interval, a busy readout's steps.\n"
      "  --truth FILE         also write the ground truth as CSV, one row per event in\n"
      "                       the same order: t_us,x,y,p,noise,lifetime_us,nx,ny,burst_index,hot,\n"
      "                       travel_px,margin_px,scorable,feature\n"
      "                       where p is +1 = ON, -1 = OFF (as in .h5 and process's .csv;\n"
      "                       the .txt writes OFF as 0), (nx, ny) is the unit direction of\n"
      "                       motion of the edge, noise rows have lifetime 0, burst_index is\n"
      "                       0 for the first event of an edge's burst and hot is 1 for\n"
      "                       hot-pixel events; travel_px is how far the edge has moved since\n"
      "                       its motion began, margin_px the distance to the border of its\n"
      "                       region (of the sensor for noise), scorable 0 where the time\n"
      "                       surface is no plane (near a rotation centre), feature the\n"
      "                       edge's index (-1 noise): what the README's accuracy figures\n"
      "                       score by (README, Synthetic scenes).\n"
      "  -q, --quiet          no summary.\n"
      "  -h, --help           this text.\n"
      "\n"
      "Exit status: 0 done; 2 bad command line; 4 output cannot be written.\n"
      "\n"
      "Examples:\n"
      "  evlife synth -o sample.txt                      # the README's sample\n"
      "  evlife process sample.txt --sensor 128x128 -o sample.csv\n"
      "  evlife synth -o bar.txt --scene bar --sensor 346x260 --duration 1 --truth bar_truth.csv\n"
      "  evlife synth -o dim.txt --scene edges-bar --sensor 346x260 --pixel dvs-dim --truth dim_truth.csv\n");
}

std::uint64_t parse_seed(const std::string& text) {
  char* end = nullptr;
  errno = 0;
  const unsigned long long v = std::strtoull(text.c_str(), &end, 10);
  if (end == text.c_str() || *end != '\0' || errno != 0 || text[0] == '-') {
    throw UsageError("--seed " + text + ": expected a non-negative integer");
  }
  return v;
}

// The pixel options override the --pixel setting's values (dvs, dvs-dim only).
void apply_pixel_options(const ParsedArgs& a, io::PixelModel& m) {
  for (const io::PixelParameter& f : io::pixel_parameters()) {
    const auto v = a.value(f.name);
    if (!v) continue;
    if (!m.enabled) throw UsageError(std::string("--") + f.name + " needs --pixel dvs or dvs-dim");
    m.*f.field = parse_number<double>(f.name, *v, f.lo, f.hi);
  }
}

// Ground truth as CSV (a tiny writer: this file is its only user).
class TruthCsv {
 public:
  explicit TruthCsv(const std::string& path) : path_(path), folder_problem_(io::create_output_folders(path)),
                                                 file_(std::fopen(path.c_str(), "wb")) {
    if (file_ == nullptr) {
      throw io::WriteError(path, folder_problem_.empty() ? std::string("cannot create: ") + std::strerror(errno)
                                                         : folder_problem_);
    }
    put("t_us,x,y,p,noise,lifetime_us,nx,ny,burst_index,hot,travel_px,margin_px,scorable,feature\n");
  }
  ~TruthCsv() {
    if (file_ != nullptr) std::fclose(file_);
  }
  TruthCsv(const TruthCsv&) = delete;
  TruthCsv& operator=(const TruthCsv&) = delete;

  void write(std::span<const Event> events, std::span<const io::EventTruth> truth) {
    char line[224];
    for (std::size_t i = 0; i < events.size(); ++i) {
      const Event& e = events[i];
      const io::EventTruth& t = truth[i];
      const int n = std::snprintf(line, sizeof line, "%lld,%u,%u,%d,%d,%.6g,%.6f,%.6f,%u,%d,%.6g,%u,%d,%d\n",
                                  static_cast<long long>(e.t_us), static_cast<unsigned>(e.x),
                                  static_cast<unsigned>(e.y), e.p > 0 ? 1 : -1, t.is_noise ? 1 : 0,
                                  t.lifetime_us, t.nx, t.ny, static_cast<unsigned>(t.burst_index),
                                  t.is_hot ? 1 : 0, t.travel_px, static_cast<unsigned>(t.margin_px),
                                  t.scorable ? 1 : 0, static_cast<int>(t.feature));
      if (std::fwrite(line, 1, static_cast<std::size_t>(n), file_) != static_cast<std::size_t>(n)) {
        throw io::WriteError(path_, std::string("write failed: ") + std::strerror(errno), errno);
      }
    }
  }
  void close() {
    if (file_ == nullptr) return;
    const bool ok = std::fclose(file_) == 0;
    file_ = nullptr;
    if (!ok) throw io::WriteError(path_, std::string("cannot flush/close the file: ") + std::strerror(errno), errno);
  }

 private:
  void put(const char* s) {
    if (std::fputs(s, file_) < 0)
      throw io::WriteError(path_, std::string("write failed: ") + std::strerror(errno), errno);
  }
  std::string path_;
  std::string folder_problem_;  // why the folders above path_ could not be made, if they could not
  std::FILE* file_;
};

int synth(int argc, char** argv) {
  io::SceneSpec spec;                          // the scene, or what the summary prints of the textured one
  std::optional<io::TexturedSceneSpec> textured;  // --scene textured
  std::string output, truth_path, scene_name = "mixed", pixel_name;
  bool quiet = false;
  if (const auto done = start_command("synth", argc, argv, print_help, [&] {
    const ParsedArgs a = parse_args(argc, argv, kOptions);
    if (!a.positional.empty()) throw UsageError("unexpected argument '" + a.positional[0] + "'");
    if (!a.has("output")) throw UsageError("missing -o FILE");
    output = *a.value("output");
    if (!has_extension(output, {".txt", ".h5", ".hdf5"})) {
      throw UsageError("-o " + output + ": synth writes .txt or .h5 (events; `evlife process` writes .csv and .bin)");
    }
    truth_path = a.value("truth").value_or("");
    // The truth is CSV: a name of another format's extension made a file its readers refuse.
    if (!truth_path.empty() && has_extension(truth_path, {".h5", ".hdf5", ".bin", ".npy", ".npz", ".mat", ".aedat4"}))
      throw UsageError("--truth " + truth_path + ": the ground truth is written as CSV; name it .csv");
    scene_name = a.value("scene").value_or("mixed");
    const SensorSize sensor = parse_sensor_size(a.value("sensor").value_or("128x128"));
    // One range said for every refused value (a negative one was told the time flags' general
    // "0 or at least 1us", then 0 and 1us were refused with this).
    const std::string duration_text = a.value("duration").value_or("3");
    const std::optional<std::int64_t> duration = parse_time_us(duration_text);
    if (!duration || *duration < 1000 || *duration > 3600'000'000)
      throw UsageError("--duration " + duration_text + ": expected 1ms..3600s (e.g. 1.5s, 500ms, or seconds)");
    const std::int64_t duration_us = *duration;
    const std::uint64_t seed = parse_seed(a.value("seed").value_or("1"));
    const bool is_textured = scene_name == "textured";
    if (is_textured) {  // its spec is filled from `spec` below, once the pixels are set
      spec = {};
      spec.sensor = sensor;
      spec.duration_us = duration_us;
      spec.seed = seed;
    } else {
      const auto preset = io::scene_preset(scene_name, sensor, duration_us, seed);
      if (!preset) {
        throw UsageError("--scene " + scene_name + ": expected edges, bar, mixed, large, edges-bar or textured");
      }
      spec = *preset;
    }
    pixel_name = a.value("pixel").value_or(is_textured ? "dvs" : "ideal");
    if (!io::apply_pixel_setting(spec, pixel_name)) {
      throw UsageError("--pixel " + pixel_name + ": expected ideal, dvs or dvs-dim");
    }
    if (is_textured && !spec.pixel.enabled) throw UsageError("--scene textured: needs --pixel dvs or dvs-dim");
    if (is_textured && a.has("contrast")) throw UsageError("--contrast: the textured scene's leaves set the contrasts");
    apply_pixel_options(a, spec.pixel);
    if (const auto r = a.value("noise-rate")) spec.noise_rate_hz_per_px = parse_number<double>("noise-rate", *r, 0.0, 1e4);
    if (const auto j = a.value("jitter-us")) {
      if (spec.pixel.enabled)  // the pixel model times its events by latency and latency jitter
        throw UsageError("--jitter-us is the ideal pixels' timing; with --pixel " + pixel_name + ": --latency-jitter-us");
      spec.jitter_sigma_us = parse_number<double>("jitter-us", *j, 0.0, 1e5);
    }
    quiet = a.has("quiet");
    if (!truth_path.empty() && io::outputs_name_one_file(truth_path, output))
      throw UsageError("--truth and -o name the same file");
    if (is_textured) {
      textured = io::textured_scene_like(spec);
      if (const auto err = io::validate_textured_scene_spec(*textured); !err.empty()) throw UsageError(err);
    } else if (const auto err = io::validate_scene_spec(spec); !err.empty()) {
      throw UsageError(err);
    }
    if (const auto refusal = textured ? scene_memory_refusal(*textured) : scene_memory_refusal(spec))
      throw UsageError(*refusal);
  })) {
    return *done;
  }

  // Bars stream slice by slice; the texture is generated whole.
  std::optional<io::SyntheticSceneReader> bars;
  std::optional<io::SceneMemoryReader> texture;
  std::vector<std::string> names;
  const std::function<std::size_t(std::span<Event>, std::span<io::EventTruth>)> next =
      [&](std::span<Event> e, std::span<io::EventTruth> t) {
        return texture ? texture->read_with_truth(e, t) : bars->read_with_truth(e, t);
      };
  std::vector<Event> events(kBatchEvents);
  std::vector<io::EventTruth> truth(kBatchEvents);
  unsigned long long written = 0, truth_rows = 0, noise = 0, hot = 0;
  std::int64_t last_t_us = 0;
  bool stopped = false;
  try {
    // The outputs open first: a bad file name is reported before seconds of generation.
    auto writer = io::open_event_writer(output, spec.sensor);  // .h5 states it; .txt cannot
    std::unique_ptr<TruthCsv> truth_csv;
    if (!truth_path.empty()) truth_csv = std::make_unique<TruthCsv>(truth_path);
    if (textured) {
      texture.emplace(io::generate_textured_scene(*textured));
      names = texture->scene().feature_names;
    } else {
      bars.emplace(spec);
      names = io::scene_feature_names(spec);
    }
    const StopRequest stop;
    while (const std::size_t n = next(events, truth)) {
      if ((stopped = stop.requested())) break;  // Ctrl-C: close a complete, shorter file
      last_t_us = events[n - 1].t_us;
      writer->write(std::span<const Event>(events.data(), n));
      written += n;
      if (truth_csv) {
        truth_csv->write(std::span<const Event>(events.data(), n), std::span(truth.data(), n));
        truth_rows += n;
      }
      for (std::size_t i = 0; i < n; ++i) {
        noise += truth[i].is_noise ? 1 : 0;
        hot += truth[i].is_hot ? 1 : 0;
      }
    }
    writer->close();
    if (truth_csv) truth_csv->close();
  } catch (const io::WriteError& e) {
    // Each file's own count: a ground truth that fails after its batch went to -o has fewer rows.
    std::fprintf(stderr, "evlife synth: output error: %s (%llu events handed to the writer of %s", e.what(), written,
                 output.c_str());
    if (!truth_path.empty()) std::fprintf(stderr, ", %llu rows to that of %s", truth_rows, truth_path.c_str());
    std::fprintf(stderr, " before it)\n");
    return kExitOutput;
  }
  if (stopped) {
    std::fprintf(stderr,
                 "evlife synth: interrupted: %s holds the scene's first %.6f s, %llu events (a complete file, cut "
                 "short)%s\n",
                 output.c_str(), static_cast<double>(last_t_us) * 1e-6, written,
                 truth_path.empty() ? "" : "; so does the ground truth");
    return kExitInterrupted;
  }
  if (!quiet) {
    std::fprintf(stdout,
                 "evlife synth: %s: scene %s, %dx%d, %.3f s, seed %llu: %llu events (%llu noise, ",
                 output.c_str(), scene_name.c_str(), spec.sensor.width, spec.sensor.height,
                 static_cast<double>(spec.duration_us) * 1e-6,
                 static_cast<unsigned long long>(spec.seed), written, noise);
    if (spec.pixel.enabled) {
      const io::PixelModel& m = spec.pixel;
      std::fprintf(stdout,
                   "%llu hot; pixels %s: %scontrast %g, threshold %g +- %g, blur %g px, latency %g +- %g us, "
                   "refractory %g us",
                   hot, pixel_name.c_str(), textured ? "texture " : "",
                   textured ? textured->texture_contrast_log : m.contrast_log, m.threshold_log, m.threshold_mismatch_sigma,
                   m.edge_blur_px, m.latency_us, m.latency_jitter_us, m.refractory_us);
      if (m.cutoff_hz > 0.0) std::fprintf(stdout, ", photoreceptor %g Hz", m.cutoff_hz);
      if (m.timestamp_quantum_us > 1.0) std::fprintf(stdout, ", stamps in %g us steps", m.timestamp_quantum_us);
      std::fprintf(stdout, ")\n");
    } else {
      std::fprintf(stdout, "jitter sigma %g us)\n", spec.jitter_sigma_us);
    }
    for (std::size_t i = 0; i < names.size() && i < 8; ++i) std::fprintf(stdout, "  %s\n", names[i].c_str());
    if (names.size() > 8) std::fprintf(stdout, "  ... and %zu more patterns\n", names.size() - 8);
    if (!truth_path.empty()) std::fprintf(stdout, "  ground truth: %s\n", truth_path.c_str());
  }
  return kExitOk;
}

}  // namespace

EVLIFE_REGISTER_COMMAND("synth", "write a synthetic scene with known ground truth (a sample)",
                        synth);

}  // namespace evlife::cli::synth_command
