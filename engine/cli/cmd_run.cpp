// `evlife run --source SPEC [...]`: the real-time engine. A source thread
// feeds a recording (as fast as possible or paced by its event clock) or the
// DVS128 camera through lock-free queues to worker threads that own tiles of
// each polarity; the merge back into input order runs on the worker that
// completes a chunk (a backstop thread finishes the stream).
// SIGINT/SIGTERM/SIGHUP end the run cleanly: everything accepted is processed and
// written, the summary printed.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <sys/resource.h>

#include <fmt/format.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "arg_parser.h"
#include "busy_pixels.h"
#include "command_start.h"
#include "command.h"
#include "earlier_frames_warning.h"
#include "instants_after_end_warning.h"
#include "memory_check.h"
#include "stop_signals.h"
#include "video_flag.h"
#include "evlife/config/config.h"
#include "evlife/engine/dvs128_source.h"
#include "evlife/engine/engine.h"
#include "evlife/engine/realtime_thread.h"
#include "evlife/engine/render_stage.h"
#include "evlife/engine/replay_source.h"
#include "evlife/engine/tile_layout.h"
#include "evlife/engine/writer_sink.h"
#include "evlife/io/augmented_event_writer.h"
#include "evlife/io/event_reader.h"
#include "evlife/io/output_path.h"
#include "evlife/io/synthetic_scene.h"
#include "evlife/io/stop.h"
#include "evlife/io/stream_copy_name.h"
#include "evlife/io/textured_scene.h"
#include "evlife/render/frame_clock.h"
#include "evlife/render/frame_composer.h"
#include "evlife/render/output_kind.h"
#include "evlife/render/render_recording.h"
#include "exit_code.h"
#include "input_spool.h"
#include "lifetime_summary.h"
#include "window_frame_sink.h"

namespace evlife::cli::run_command {
namespace {

std::atomic<engine::Engine*> g_engine{nullptr};
static_assert(std::atomic<engine::Engine*>::is_always_lock_free);
extern "C" void on_run_signal(int) {
  // Async-signal-safe: atomic operations, no allocation, no lock. The stop
  // flag too: a write to a FIFO whose reader takes nothing heeds it.
  g_stop_requested.store(true);
  if (engine::Engine* e = g_engine.load()) e->request_stop();
}

constexpr OptionSpec kOptions[] = {
    {"source", 0, true, false},       {"sensor", 0, true, false},
    kInputOptionSpec, kTopicOptionSpec, kTimeUnitOptionSpec, kPolarityOptionSpec, kFromOptionSpec,
    kToOptionSpec,
    {"realtime", 0, true, false},     {"workers", 'j', true, false},
    {"tiles", 0, true, false},        {"margin", 0, true, false},
    {"policy", 0, true, false},       {"batch-events", 0, true, false},
    {"queue-batches", 0, true, false}, {"stats-period", 0, true, false},
    {"fps", 0, true, false, "render-fps"}, {"frames", 0, true, false},
    {"video", 0, true, false},        {"mode", 'm', true, false, "render-mode"},
    {"window", 0, false, false},     {"at", 0, true, false},
    {"output", 'o', true, false},
    {"biases", 0, true, false},       {"duration", 0, true, false},
    kConfigOptionSpec, kSetOptionSpec, kPrintConfigOptionSpec,
    {"idle-spin-us", 0, true, false}, {"packet-us", 0, true, false},
    {"cpus", 0, true, false},         {"rt-priority", 0, true, false},
    {"lock-memory", 0, false, false},
    {"quiet", 'q', false, false},     {"help", 'h', false, false},
};

void print_help(std::FILE* out) {
  std::fprintf(out,
      "evlife run — the real-time engine: lifetimes and velocities of a live or\n"
      "replayed event stream, on several threads, with bounded latency and memory\n"
      "\n"
      "Usage: evlife run [--source] SPEC [--sensor WxH] [--realtime[=K]] [--workers N]\n"
      "                  [--tiles CxR] [--margin PX] [--policy block|drop] [-o OUT]\n"
      "                  [--from T] [--to T] [--fps F] [--at T1,T2,...]\n"
      "                  [--frames DIR | --video FILE | --window]\n"
      "                  [--cpus LIST] [--rt-priority P] [--lock-memory]\n"
      "                  [--config FILE] [--set KEY=VALUE]... [--quiet]\n"
      "       evlife run synth:PRESET [--duration T] ...\n"
      "       evlife run dvs128[:SERIAL] [--biases FILE] ...\n"
      "\n"
      "Threads: one source thread (reads and routes), N worker threads (each runs\n"
      "its own estimator on the tiles it owns, then merges what it completed back\n"
      "into input order and writes it, unless another worker is doing so), one\n"
      "output thread as a backstop (end of stream, render room), a render thread\n"
      "with --frames/--video, and this thread (progress, signals). Bounded queues\n"
      "between them, fixed at start.\n"
      "\n"
      "Sources (--source):\n"
      "  file:PATH | PATH     a recording, any format `evlife process` reads (also as\n"
      "                       `evlife run PATH` or -i/--input PATH); replayed\n"
      "                       as fast as the workers go, or paced with --realtime.\n"
      "  dvs128[:SERIAL]      the DVS128 camera over USB (--biases FILE); a live\n"
      "                       source: runs until SIGINT; a vanished camera ends the\n"
      "                       run with exit status 3 after writing what arrived.\n"
      "  synth:PRESET         a synthetic scene (edges, bar, mixed, large, edges-bar) of\n"
      "                       --duration T (default 1s; 500ms ...) on --sensor (default\n"
      "                       1280x720); live-like: paced with --realtime. synth:textured:\n"
      "                       the texture of `evlife synth --scene textured` (dvs pixels,\n"
      "                       default 346x260, generated whole before the run).\n"
      "\n"
      "Options:\n"
      "  --sensor WxH         sensor size when the format does not state one (else\n"
      "                       scanned from the data).\n"
      );
  std::fputs((std::string(kInputOptionsHelp) + std::string(kCropOptionsHelp)).c_str(), out);
  std::fprintf(out,
      "  --realtime[=K]       pace a replay by its event clock at K x real time\n"
      "                       (default 1). Without it: as fast as possible.\n"
      "  --tiles CxR          tiles per polarity (default 1x1: one worker per\n"
      "                       polarity, output identical to `evlife process`). The\n"
      "                       2*C*R tiles are dealt to the workers round robin (so\n"
      "                       --workers is at most 2*C*R). Tiled\n"
      "                       output differs from the single-threaded one on a small\n"
      "                       share of events near borders (see README; --margin),\n"
      "                       and so between --workers counts that deal the tiles\n"
      "                       differently (a worker's estimator sees its tiles\n"
      "                       together); for one count it is the same every run.\n"
      "  --policy block|drop  when workers fall behind: block the source (default for\n"
      "                       files) or drop and count (default for cameras).\n"
      "Engine options (defaults: the engine: section of the configuration; -j = --workers):\n");
  std::fputs(table_flags_help([](auto f) { engine::for_each_engine_option(f); }).c_str(), out);
  std::fprintf(out,
      "  -o, --output FILE    write the augmented stream, in input order: FILE.csv,\n"
      "                       FILE.bin or FILE.h5 (as `evlife process`). Without\n"
      "                       -o: discarded (counted), e.g. to measure throughput.\n"
      "  --frames DIR         a render thread draws the active events (each event\n"
      "                       shown for its lifetime, coloured by it) to numbered PNGs\n"
      "                       DIR/frame_NNNNNN_t<seconds>s.png, as `evlife render` ...\n"
      "  --video FILE         ... or to a video (.mp4 or .avi) playing at --fps (real\n"
      "                       time) up to 60 fps; slow motion beyond.\n"
      "  --window             ... or to an on-screen window (needs a display; q, Esc\n"
      "                       or closing the window stops the run as SIGINT does).\n"
      "                       With --realtime it plays at the recording's pace.\n"
      "  --fps F              frames per second of the EVENT clock (default 30), from\n"
      "                       the first event on: `evlife render --fps`'s frames, at\n"
      "                       any replay speed; 0: only --at frames.\n"
      "  --at T1,T2,...       also draw these instants, seconds from the first event\n"
      "                       (or 250ms, 40us), e.g. --fps 0 --at 0.25,0.5. With --from,\n"
      "                       instants and frame names count from the first event read\n"
      "                       (`evlife render` counts from the file's first event).\n"
      "  -m, --mode M         lifetime | window:30ms | compare (as `evlife render`).\n"
      "                       (--render-fps and --render-mode are accepted too.)\n"
      "                       With policy drop the render branch skips what it cannot\n"
      "                       keep up with (counted); with block it slows the run.\n"
      "Real time (Linux; each refused setting stops the run before it starts, exit 5):\n"
      "  --cpus LIST          pin the threads, one CPU each in this order, cycling:\n"
      "                       source, workers 0..N-1, merger, render (e.g. 0,1 or 1-3).\n"
      "  --rt-priority P      SCHED_FIFO priority 1..99 for the source, worker and\n"
      "                       merger threads (needs CAP_SYS_NICE or ulimit -r >= P);\n"
      "                       idle polling then stays off unless --idle-spin-us (or\n"
      "                       engine.idle_spin_us) is set: polling FIFO threads trip\n"
      "                       the kernel's RT throttling.\n"
      "  --lock-memory        mlockall: pools, estimator state, queues and thread\n"
      "                       stacks faulted in and locked before the first event\n"
      "                       (needs CAP_IPC_LOCK or a large enough ulimit -l).\n"
      "                       The summary's `realtime` line states what was applied.\n"
      "  -q, --quiet          no progress and no summary.\n");
  std::fputs(config_options_help().c_str(), out);
  std::fprintf(out,
      "\n"
      "At the end (and on SIGINT, SIGTERM or SIGHUP, after finishing the queued\n"
      "work) a summary per stage goes to stdout: events in/out/dropped (in = out +\n"
      "dropped), queue high-water marks, worker load, latency from arrival to\n"
      "output p50/p99/max; the output's share labelled noise and with a prediction,\n"
      "and over 0.5 s or more the pixels firing at 100 Hz or more (hot pixels).\n"
      "\n"
      "Exit status: 0 done; 2 bad command line or configuration; 3 input/device\n"
      "             error; 4 output error; 5 real-time setting refused; 130\n"
      "             interrupted (all accepted work written).\n"
      "\n"
      "Examples:\n"
      "  evlife run --source file:stripes.mat --workers 2 -o stripes.bin\n"
      "  evlife run --source stripes.mat --realtime=0.5 --tiles 2x2 --workers 2\n"
      "  evlife run --source dvs128 -o live.bin\n");
}

struct RunArgs {
  std::string source;
  std::optional<SensorSize> sensor;       // --sensor
  std::optional<SensorSize> user_sensor;  // --sensor, else a configured estimator.sensor
  io::ReaderOptions input_options;  // --topic
  double speed = 0.0;
  std::string output;
  std::optional<io::Dvs128Biases> biases;  // --biases FILE, read while parsing
  std::string frames_dir;
  std::string video;
  bool window = false;
  engine::RenderOptions render;
  double duration_s = 1.0;
  bool quiet = false;
  bool print_config = false;
  config::LoadedConfig config;
  engine::EngineOptions engine;
};

// The recording a file source names: `file:PATH` or `PATH`.
std::string_view file_of_source(std::string_view spec) {
  return spec.starts_with("file:") ? spec.substr(5) : spec;
}
bool is_file_source(std::string_view spec) { return !engine::is_dvs128_spec(spec) && !spec.starts_with("synth:"); }

// The engine's options: the configuration's, then its flags over them
// (with --print-config too, which shows them).
engine::EngineOptions engine_flags(const ParsedArgs& a, const config::Config& config) {
  // The configuration file first, then the flags override it: every flag of
  // the engine's option table (engine_options.h), with the table's range.
  engine::EngineOptions e = config.engine;
  e.lifetime = config.estimator;
  engine::for_each_engine_option([&](const OptionInfo& info, auto field) {
    if (info.flag.empty()) return;
    if (const auto s = a.value(info.flag)) parse_table_flag(info, *s, field(e));
  });
  if (const auto s = a.value("tiles")) {
    const auto x = s->find('x');
    if (x == std::string::npos) throw UsageError("--tiles " + *s + ": expected CxR, e.g. 2x2");
    e.tiles_x = parse_number<int>("tiles", s->substr(0, x), 1, 256);
    e.tiles_y = parse_number<int>("tiles", s->substr(x + 1), 1, 256);
  }
  // A flag that would change nothing is refused (it was accepted and ignored).
  if (a.has("margin") && e.margin_px > 0 && e.tiles_x == 1 && e.tiles_y == 1)
    throw UsageError("--margin " + std::string(*a.value("margin")) +
                     ": with --tiles 1x1 each worker's estimator sees its polarity's whole sensor, with no margin to "
                     "process; margins are for tiled layouts (e.g. --tiles 2x2 --margin 8)");
  // Workers beyond the tiles would get no event and hold an estimator's memory each.
  // Whether the count came from --workers or the configuration (--set, --config: it passed silently).
  if (const int tiles = 2 * e.tiles_x * e.tiles_y; e.workers > tiles)
    throw UsageError((a.has("workers") ? "--workers " + std::to_string(e.workers)
                                       : "engine.workers = " + std::to_string(e.workers) + " (--set or --config)") +
                     ": --tiles " + std::to_string(e.tiles_x) + "x" +
                     std::to_string(e.tiles_y) + " makes " + std::to_string(tiles) +
                     " tiles (per polarity), which keep at most " + std::to_string(tiles) +
                     " workers busy; the others would get no event. Use --workers " + std::to_string(tiles) +
                     " or more tiles (2*C*R >= workers, e.g. --tiles 2x2 for up to 8)");
  if (const auto s = a.value("policy")) {
    if (*s == "auto" || !engine::parse_overload_policy(*s, e.auto_policy, e.policy))
      throw UsageError("--policy " + *s + ": expected block or drop");
  }
  if (const auto s = a.value("cpus")) {
    try {
      e.realtime.cpus = engine::parse_cpu_list(*s);
    } catch (const std::invalid_argument& ex) {
      throw UsageError(ex.what());
    }
  }
  if (const auto s = a.value("rt-priority")) e.realtime.rt_priority = parse_number<int>("rt-priority", *s, 1, 99);
  e.realtime.lock_memory = a.has("lock-memory");
  return e;
}

RunArgs parse_run_args(int argc, char** argv) {
  // `--realtime` alone means 1x: give it its value before generic parsing.
  std::vector<std::string> storage(argv, argv + argc);
  for (auto& a : storage)
    if (a == "--realtime") a = "--realtime=1";
  std::vector<char*> args;
  for (auto& a : storage) args.push_back(a.data());
  const ParsedArgs a = parse_args(static_cast<int>(args.size()), args.data(), kOptions);

  RunArgs r;
  r.quiet = a.has("quiet");
  r.config = load_command_config(a);
  r.print_config = a.has("print-config");
  r.engine = engine_flags(a, r.config.config);
  if (const auto s = a.value("sensor")) r.sensor = parse_sensor_size(*s);  // (--print-config shows it)
  if (r.print_config) {  // the engine's flags shown as the configuration they make
    r.config.config.engine = r.engine;
    return r;
  }
  if (a.positional.size() > 1) throw UsageError("unexpected argument '" + a.positional[1] + "'");
  const auto src = a.value("source");
  if (src && !a.positional.empty())
    throw UsageError("give the source once: --source " + *src + " or " + a.positional.front());
  if (!src && a.positional.empty())
    throw UsageError("missing --source (file:PATH or PATH, dvs128[:SERIAL] or synth:PRESET)");
  r.source = src ? *src : a.positional.front();  // `run FILE` = --source FILE
  if (is_file_source(r.source) && file_of_source(r.source).empty())
    throw UsageError("--source " + r.source + ": a file source needs a path (file:PATH or PATH)");
  r.user_sensor = user_sensor_size(r.sensor, r.config);
  r.input_options = parse_input_options(a);
  if (const auto s = a.value("realtime")) r.speed = parse_number<double>("realtime", *s, 1e-6, 1e6);
  if (const auto s = a.value("output")) {
    if (s->empty()) throw UsageError("-o needs a file name (.csv, .bin or .h5); without -o the output is discarded");
    r.output = *s;
  }
  if (const auto s = a.value("duration")) {
    if (!r.source.starts_with("synth:"))
      throw UsageError("--duration sets a synth: scene's length; " + r.source + " runs to its end (a file: --to T)");
    r.duration_s = static_cast<double>(parse_time_flag("duration", *s)) * 1e-6;
    if (r.duration_s < 1e-3 || r.duration_s > 3600)
      throw UsageError("--duration " + *s + ": expected 1ms..3600s");
  }
  if (const std::string flags = selecting_flags(r.input_options); !flags.empty() && !is_file_source(r.source))
    throw UsageError(flags + " select the events of a file; the source " + r.source + " is none");
  if (const auto s = a.value("frames")) {
    if (s->empty()) throw UsageError("--frames needs a folder");
    r.frames_dir = *s;
  }
  if (const auto s = a.value("video")) {
    r.video = *s;
    if (render::output_kind(r.video) != render::OutputKind::video)
      throw UsageError(video_flag_refusal(r.video));
  }
  if (const auto s = a.value("mode")) {
    r.render.mode = *s;
    // as `evlife render`: a bad mode is the command line's error, before any file is touched
    (void)parse_flag_with("mode", [&] { return render::parse_view_mode(r.render.mode); });
  }
  if (const auto s = a.value("fps")) {  // 0: only the --at instants
    r.render.fps = parse_number<double>("fps", *s, 0, 100000);
    if (r.render.fps != 0 && r.render.fps < render::kMinFps) {
      char range[64];
      std::snprintf(range, sizeof range, "0 (the --at instants only) or a number in [%g, 100000]", render::kMinFps);
      throw UsageError("--fps " + *s + ": expected " + range);
    }
  }
  if (const auto s = a.value("at")) r.render.at_us = parse_instants_us("at", *s, "run");
  if (!r.video.empty() && r.render.fps == 0)
    throw UsageError("--video needs --fps > 0 (it plays at that rate)");
  if (a.has("fps") && r.render.fps == 0 && r.render.at_us.empty())
    throw UsageError("--fps 0 draws only the --at instants, and none is given: add --at T1,T2,... or --fps > 0");
  if (!r.video.empty() && r.render.fps < render::kMinVideoFps) {  // the encoders refuse it
    char text[96];
    std::snprintf(text, sizeof text, "--video plays at --fps: at least %g (a frame each %g s)", render::kMinVideoFps,
                  1.0 / render::kMinVideoFps);
    throw UsageError(text);
  }
  r.window = a.has("window");
  if (int{!r.frames_dir.empty()} + int{!r.video.empty()} + int{r.window} > 1)
    throw UsageError("--frames, --video and --window: choose one");
  if ((a.has("fps") || a.has("mode") || a.has("at")) && r.frames_dir.empty() &&
      r.video.empty() && !r.window)
    throw UsageError("--fps/--mode/--at need --frames DIR, --video FILE or --window");

  if (!r.output.empty()) {
    if (!io::names_an_augmented_output(r.output))
      throw UsageError("-o " + r.output + ": the output must end in .csv, .bin or .h5");
    if (const auto refusal = io::output_overwrites_input(std::string(file_of_source(r.source)), r.output))
      throw UsageError("-o " + *refusal);
  }
  if (const auto refusal = io::output_overwrites_input(std::string(file_of_source(r.source)), r.video))
    throw UsageError("--video " + *refusal);
  const auto biases_file = a.value("biases");
  if (biases_file && biases_file->empty())
    throw UsageError("--biases needs a file of `name: value` lines; without --biases the built-in biases are sent");
  if (biases_file && !engine::is_dvs128_spec(r.source))
    throw UsageError("--biases sets a DVS128 camera's biases: the source " + r.source + " has none");
  if (engine::is_dvs128_spec(r.source)) {  // a camera streams at its own pace, on its own sensor
    for (const char* replay_only : {"realtime", "packet-us", "sensor"}) {
      if (a.has(replay_only))
        throw UsageError(std::string("--") + replay_only + " sets a replay or a synth: scene; the camera " + r.source +
                         (std::string_view(replay_only) == "sensor" ? " is 128x128" : " streams at its own pace"));
    }
  } else if (a.has("packet-us") && r.speed <= 0) {  // (the camera's case is refused above)
    throw UsageError("--packet-us sets the packets of a paced replay: add --realtime (unpaced, a replay hands "
                     "its events over as fast as the workers take them)");
  }
  if (biases_file) {  // last: read once (a pipe reads once), and only for a command line found valid
    try {
      r.biases = io::Dvs128Biases::load_file(*biases_file);
    } catch (const std::runtime_error& e) {  // a bad setting, as a bad --config
      throw config::ConfigError(e.what());
    }
  }
  return r;
}

// `stop`: a signal during a file's scan for its sensor size ends the scan.
std::unique_ptr<engine::EventSource> make_source(const RunArgs& r, const std::atomic<bool>* stop) {
  std::string_view spec = r.source;
  if (engine::is_dvs128_spec(spec)) return engine::make_dvs128_source(spec, r.biases.value_or(io::Dvs128Biases{}));
  if (spec.starts_with("synth:")) {
    const auto duration_us = std::llround(r.duration_s * 1e6);  // 0.2 s: 199999.99999999997 us
    std::unique_ptr<io::EventReader> scene;
    SensorSize sensor{};
    if (spec == "synth:textured") {  // generated whole (~70 B per event): a DAVIS346 by default
      io::TexturedSceneSpec texture;
      texture.sensor = sensor = r.user_sensor.value_or(SensorSize{346, 260});
      texture.duration_us = duration_us;
      if (const std::string why = io::validate_textured_scene_spec(texture); !why.empty()) throw UsageError(why);
      if (const auto refusal = scene_memory_refusal(texture))
        throw UsageError("--source " + r.source + ": " + *refusal);
      scene = std::make_unique<io::SceneMemoryReader>(io::generate_textured_scene(texture));
    } else {
      sensor = r.user_sensor.value_or(SensorSize{1280, 720});
      const auto preset = io::scene_preset(spec.substr(6), sensor, duration_us, 1);
      if (!preset) {
        throw UsageError("--source " + r.source + ": unknown preset (edges, bar, mixed, large, edges-bar, textured)");
      }
      if (const auto refusal = scene_memory_refusal(*preset))
        throw UsageError("--source " + r.source + ": " + *refusal);
      scene = std::make_unique<io::SyntheticSceneReader>(*preset);
    }
    auto source = engine::ReplaySource::from_reader(std::move(scene), sensor, r.speed,
                                                    r.speed > 0 ? engine::SourceKind::live : engine::SourceKind::offline);
    source->set_packet_us(r.engine.replay_packet_us);
    source->describe_as(fmt::format("{} (a generated scene, {}x{}, {:g} s)", r.source, sensor.width, sensor.height,
                                    static_cast<double>(duration_us) * 1e-6));
    return source;
  }
  auto source =
      engine::ReplaySource::open_file(std::string(file_of_source(spec)), r.user_sensor, r.speed, r.input_options, stop);
  source->set_packet_us(r.engine.replay_packet_us);
  return source;
}

// The merged output on its way to the file (or nowhere), counted for the
// summary: the shares `evlife process` prints, without its histograms (their
// logarithm per event would cost the pipeline ~10 %), and its busy pixels.
// Runs on the thread that merges; read after the run.
class CountingSink final : public engine::AugmentedSink {
 public:
  CountingSink(engine::AugmentedSink* next, std::optional<SensorSize> sensor)
      : next_(next), sensor_(sensor), busy_pixels_(sensor) {}
  void write(std::span<const AugmentedEvent> events) override {
    if (next_ != nullptr) next_->write(events);  // a refused block is not counted
    if (!events.empty()) {
      if (events_ == 0) first_t_us_ = events.front().event.t_us;
      last_t_us_ = events.back().event.t_us;
    }
    events_ += events.size();
    for (const AugmentedEvent& a : events) {
      noise_ += a.is_noise();
      predictions_ += a.has_prediction();
      // The estimators' rule, here once for all workers (a tile's margin feeds an event to several).
      if (const Rejection why = sensor_ ? rejection_of(a.event, *sensor_) : Rejection::none; why != Rejection::none) {
        ++rejected_.rejected_counter(why);
      }
      busy_pixels_.add(a);
    }
  }
  void finish() override {
    if (next_ != nullptr) next_->finish();
  }
  void print(std::FILE* out) const {
    const auto share = [&](std::uint64_t part) {
      return events_ == 0 ? 0.0 : 100.0 * static_cast<double>(part) / static_cast<double>(events_);
    };
    std::fprintf(out, "output : %llu events to the writer, labelled noise %.1f %%, with a prediction %.1f %% "
                 "(lifetimes: evlife process)\n",
                 static_cast<unsigned long long>(events_), share(noise_), share(predictions_));
    if (rejected_.rejected() > 0) {
      std::fprintf(out, "rejected: %s (labelled noise unexamined)\n", rejected_events_text(rejected_).c_str());
    }
    if (const auto busy = busy_pixels_.report(seconds_between(first_t_us_, last_t_us_), events_)) {
      const std::string meaning = busy->pixels > 0 ? std::string(" (") + BusyPixels::kMeaning + ")" : "";
      std::fprintf(out, "pixels : at >= %.0f Hz %s%s\n", BusyPixels::kMinRateHz, busy->text.c_str(),
                   meaning.c_str());
    }
  }

 private:
  engine::AugmentedSink* next_;
  std::optional<SensorSize> sensor_;
  LifetimeStats rejected_;  // its rejection counters only
  std::uint64_t events_ = 0;
  std::uint64_t noise_ = 0;
  std::uint64_t predictions_ = 0;
  std::int64_t first_t_us_ = 0;
  std::int64_t last_t_us_ = 0;
  BusyPixels busy_pixels_;
};

void print_run_summary(const RunArgs& args, const engine::EventSource& src,
                       const engine::RunResult& result, const engine::RenderStage* render_stage,
                       double wall_s) {
  std::fprintf(stdout, "evlife run: %s -> %s\n%s\n", src.describe().c_str(),
               args.output.empty() ? "(discarded)" : args.output.c_str(),
               result.stats.summary().c_str());
  if (result.stats.has_time_range)
    std::fprintf(stdout, "time   : %s\n",
                 format_time_range(result.stats.first_t_us, result.stats.last_t_us).c_str());
  // Records of the file that are not events, as `evlife process` shows them.
  const auto* replay = dynamic_cast<const engine::ReplaySource*>(&src);
  if (const io::EventReader* reader = replay ? replay->reader() : nullptr;
      reader && reader->skipped_record_count() > 0) {
    std::fprintf(stdout, "skipped: %llu records %s\n", static_cast<unsigned long long>(reader->skipped_record_count()),
                 io::skipped_records_note(*reader).c_str());
  }
  if (const auto* camera = dynamic_cast<const engine::Dvs128Source*>(&src)) {
    const io::Dvs128DecoderCounters& c = camera->decoder_counters();
    std::fprintf(stdout, "camera : %llu words: %llu events, %llu special (sync), %llu timestamp wraps, %llu resets; "
                 "%llu stamped with the time of the event before them (they came earlier: a word lost or corrupt)\n",
                 static_cast<unsigned long long>(c.words), static_cast<unsigned long long>(c.pixel_events),
                 static_cast<unsigned long long>(c.sync_events), static_cast<unsigned long long>(c.wraps),
                 static_cast<unsigned long long>(c.resets), static_cast<unsigned long long>(c.time_regressions));
  }
  if (render_stage && render_stage->frames_written() == 0 && !args.video.empty()) {
    // The video is opened with its first frame: a file of that name is untouched.
    std::fprintf(stdout, "frames : none drawn: %s not written (a file of that name is left as it was)\n",
                 args.video.c_str());
  } else if (render_stage) {
    std::fprintf(stdout, "frames : %llu %s %s",
                 static_cast<unsigned long long>(render_stage->frames_written()),
                 args.window ? "shown in" : "written to",
                 args.window ? "a window" :
                 args.frames_dir.empty() ? args.video.c_str() : args.frames_dir.c_str());
    if (!args.video.empty() && args.render.fps > render::kMaxVideoFps)
      std::fprintf(stdout, " (the video plays at %g fps: slow motion)", render::kMaxVideoFps);
    if (const std::uint64_t skipped = render_stage->frames_not_drawn(); skipped > 0)
      std::fprintf(stdout, " (%llu more not drawn: stopped)", static_cast<unsigned long long>(skipped));
    if (const std::uint64_t gaps = render_stage->frames_in_skipped_gaps(); gaps > 0)
      std::fprintf(stdout, " (%llu of stretches without events skipped, not drawn: see the warnings)",
                   static_cast<unsigned long long>(gaps));
    if (const std::uint64_t incomplete = render_stage->frames_incomplete(); incomplete > 0)
      std::fprintf(stdout, " (%llu of them at instants whose events the render thread skipped: blank or partial; "
                           "frames after such a stretch may lack its long-lived events)",
                   static_cast<unsigned long long>(incomplete));
    if (const std::uint64_t missed = render_stage->frames_missed(); missed > 0)
      std::fprintf(stdout, " (%llu due not drawn: their events were dropped, the workers or the render thread behind)",
                   static_cast<unsigned long long>(missed));
    std::fprintf(stdout, "\n");
  }
  std::fprintf(stdout, "realtime: %s\n", result.realtime.c_str());
  std::string cpu;
  double threads_s = 0.0;
  for (const auto& [name, s] : result.thread_cpu_s) {
    cpu += (cpu.empty() ? "" : ", ") + name + " " + fmt::format("{:.3f}", s);
    threads_s += s;
  }
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  const double process_s = static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
                           static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) * 1e-6;
  std::fprintf(stdout, "cpu    : %s; other (start-up, main) %.3f; process %.3f s\n", cpu.c_str(),
               process_s - threads_s, process_s);
  std::fprintf(stdout, "wall   : %.3f s, %.0f events/s\n", wall_s,
               wall_s > 0 ? static_cast<double>(result.stats.events_out) / wall_s : 0.0);
  std::fflush(stdout);
}

int run_exit_status(const engine::RunResult& result, const engine::RenderStage* render_stage, bool quiet) {
  if (render_stage && !render_stage->error().empty()) {
    std::fprintf(stderr, "evlife run: frame output error: %s\n", render_stage->error().c_str());
    if (result.status == engine::RunStatus::completed) return kExitOutput;
  }
  // Drops are named whatever -q says: never a silent loss (the summary is -q's to skip).
  const auto written = static_cast<unsigned long long>(result.stats.events_out);
  const auto dropped = static_cast<unsigned long long>(result.stats.events_dropped);
  const std::string and_dropped =
      dropped == 0 ? std::string() : fmt::format(" ({} more dropped: --policy drop, the workers fell behind)", dropped);
  // Frames the render thread could not draw whole (policy drop), however the run ended.
  if (render_stage && quiet) {
    if (const std::uint64_t missed = render_stage->frames_missed(); missed > 0)
      std::fprintf(stderr, "evlife run: warning: %llu frames due not drawn (their events were dropped: the workers or "
                   "the render thread fell behind; --policy block waits instead)\n",
                   static_cast<unsigned long long>(missed));
    if (const std::uint64_t incomplete = render_stage->frames_incomplete(); incomplete > 0)
      std::fprintf(stderr, "evlife run: warning: %llu frames drawn blank or partial (their instants' events were "
                   "skipped: the render thread fell behind; --policy block waits instead)\n",
                   static_cast<unsigned long long>(incomplete));
  }
  switch (result.status) {
    case engine::RunStatus::completed:
      if (dropped > 0 && quiet) {
        std::fprintf(stderr, "evlife run: warning: %llu of %llu events dropped (--policy drop: the workers fell behind; "
                     "--policy block waits instead)\n", dropped, static_cast<unsigned long long>(result.stats.events_in));
      }
      if (result.stats.source_lost > 0 && quiet) {
        std::fprintf(stderr, "evlife run: warning: %llu events lost before the engine (the device's buffer overflowed)\n",
                     static_cast<unsigned long long>(result.stats.source_lost));
      }
      break;
    case engine::RunStatus::interrupted:
      std::fprintf(stderr, "evlife run: interrupted; all %llu accepted events were written%s\n", written,
                   and_dropped.c_str());
      break;
    case engine::RunStatus::source_error:
      std::fprintf(stderr, "evlife run: input error: %s\n"
                   "evlife run: the %llu events before it were processed and written%s\n",
                   result.message.c_str(), written, and_dropped.c_str());
      break;
    case engine::RunStatus::sink_error:
      if (io::stop_requested()) {  // a stop while the output's reader took nothing
        std::fprintf(stderr, "evlife run: interrupted; output: %s\n", result.message.c_str());
        return kExitInterrupted;
      }
      std::fprintf(stderr, "evlife run: output error: %s\n", result.message.c_str());
      break;
    case engine::RunStatus::realtime_error:
      std::fprintf(stderr, "evlife run: real-time setting refused, nothing processed: %s\n",
                   result.message.c_str());
      break;
  }
  return result.exit_code();  // the one scheme (evlife/engine/exit_code.h)
}

int run_engine(int argc, char** argv) {
  RunArgs args;
  if (const auto done = start_command("run", argc, argv, print_help, [&] {
        args = parse_run_args(argc, argv);
        const std::string problem = engine::validate_engine_options(args.engine);
        if (!problem.empty()) throw UsageError(problem);
      })) {
    return *done;
  }
  if (args.print_config) {
    print_config(args.config, args.sensor);
    return kExitOk;
  }
  std::optional<InputSpool> spool;  // a file source `-` or a pipe: replayed from a copy
  if (is_file_source(args.source)) {
    std::string file(file_of_source(args.source));
    if (const auto done = spool_stream_input("run", file, args.quiet, spool)) return *done;
    args.source = "file:" + file;
  }
  if (args.window) {  // before any thread: the probe forks
    const std::string problem = probe_window_display();
    if (!problem.empty()) {
      std::fprintf(stderr, "evlife run: %s\n", problem.c_str());
      return kExitOutput;
    }
    // Qt complains at exit that the window's timers belong to the render
    // thread; harmless, and noise in the summary. The user's rules win.
    setenv("QT_LOGGING_RULES", "default.warning=false", 0);
  }
  auto logger = spdlog::stderr_color_mt("evlife-run");
  spdlog::set_default_logger(logger);
  spdlog::set_pattern("[%H:%M:%S.%e] %v");
  if (args.quiet) spdlog::set_level(spdlog::level::warn);
  if (args.quiet) args.engine.stats_period_s = 0.0;

  // From here until the engine runs, a stop signal is noted, not fatal: the
  // scan for a sensor size ends, or the engine starts stopped, so the output
  // is closed valid with the summary (before, a signal while the output was
  // opened or the estimators allocated killed the process: an empty .bin).
  const StopRequest stop;
  std::unique_ptr<engine::EventSource> source;
  try {
    source = make_source(args, stop.flag());
  } catch (const UsageError& e) {
    std::fprintf(stderr, "evlife run: %s\n", e.what());
    return kExitUsage;
  } catch (const io::OptionNotTaken& e) {
    return usage_exit("run", e.what());
  } catch (const std::exception& e) {
    if (!stop.requested()) {  // else a stop ended the opening (a bag's decompression: io/stop.h)
      std::fprintf(stderr, "evlife run: input error: %s\n", e.what());
      return kExitInput;
    }
  }
  if (stop.requested()) {
    // (Opening may scan a file for its sensor size, decompress a bag or generate a synth: scene.)
    std::fprintf(stderr, "evlife run: interrupted while opening %s: nothing processed%s\n",
                 io::name_in_messages(std::string(file_of_source(args.source))).c_str(), args.output.empty() ? "" : fmt::format(", {} not written", args.output).c_str());
    return kExitInterrupted;
  }
  warn_user_sensor_ignored("run", args.sensor, args.config, file_of_source(args.source), source->sensor_size());
  // A size the file states (or its events span) that no estimator takes: the
  // input's fault, as `evlife process` says it (it was exit 2, a usage error).
  if (LifetimeOptions sized = args.engine.lifetime; is_file_source(args.source)) {
    sized.sensor = source->sensor_size();
    if (const std::string why = validate_lifetime_options(sized); !why.empty()) {
      std::fprintf(stderr, "evlife run: input error: %s: sensor %dx%d is not usable: %s\n", source->describe().c_str(),
                   sized.sensor.width, sized.sensor.height, why.c_str());
      return kExitInput;
    }
  }
  // Every refusal before the output is opened: opening it empties a file of that name.
  if (const auto refusal = estimator_memory_refusal(source->sensor_size(), args.engine.workers)) {
    std::fprintf(stderr, "evlife run: %s: use fewer --workers or a smaller --sensor\n", refusal->c_str());
    return kExitUsage;
  }
  if (const std::string refused = engine::probe_realtime_options(args.engine.realtime); !refused.empty()) {
    std::fprintf(stderr, "evlife run: real-time setting refused, nothing processed: %s\n", refused.c_str());
    return kExitRealtime;
  }
  // The tiling fits the sensor (known only now) before -o is opened, said
  // with the flag, its value and the sensor (the layout's own refusal,
  // "tiles_x: must be 1..min(sensor width, 4096)", named none of them).
  if (const SensorSize s = source->sensor_size(); args.engine.tiles_x > s.width || args.engine.tiles_y > s.height) {
    std::fprintf(stderr,
                 "evlife run: --tiles %dx%d: more tiles than pixels across the %dx%d sensor of %s (a tile is at least "
                 "one pixel): at most --tiles %dx%d\n",
                 args.engine.tiles_x, args.engine.tiles_y, s.width, s.height, source->describe().c_str(),
                 std::min(args.engine.tiles_x, s.width), std::min(args.engine.tiles_y, s.height));
    return kExitUsage;
  }
  try {
    const engine::TileLayout layout(source->sensor_size(), args.engine.workers, args.engine.tiles_x,
                                    args.engine.tiles_y, engine::effective_margin_px(args.engine));
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "evlife run: %s: %s\n", source->describe().c_str(), e.what());
    return kExitUsage;
  }
  // The frames of `evlife render` (its upscaling too), whatever the sensor.
  args.render.style.scale = render::FrameStyle::default_scale(source->sensor_size().width, source->sensor_size().height);
  // The frames' folder or video before -o: a bad frame path must not have
  // emptied an existing output first.
  std::unique_ptr<render::FrameSink> frame_sink;
  try {
    if (!args.frames_dir.empty()) {
      frame_sink = std::make_unique<render::PngFolderFrameSink>(args.frames_dir, std::string(file_of_source(args.source)));
    } else if (!args.video.empty()) {
      // As `evlife render`: real time up to kMaxVideoFps, slow motion beyond (an .avi at
      // thousands of fps was written corrupt).
      auto video = std::make_unique<render::VideoFrameSink>(args.video, std::min(args.render.fps, render::kMaxVideoFps));
      // Its encoder takes these frames (a frame too large for MPEG-4 failed at the end of the run).
      const cv::Size frame = render::FrameComposer(render::parse_view_mode(args.render.mode), args.render.style,
                                                   args.render.mode).frame_size(source->sensor_size());
      video->check(frame.width, frame.height);
      frame_sink = std::move(video);
    }
  } catch (const std::runtime_error& e) {
    std::fprintf(stderr, "evlife run: output error: %s%s\n", e.what(),
                 args.output.empty() ? "" : fmt::format(" ({} left as it was)", args.output).c_str());
    return kExitOutput;
  }
  std::unique_ptr<engine::WriterSink> writer_sink;
  if (!args.output.empty()) {
    try {
      writer_sink = std::make_unique<engine::WriterSink>(
          io::open_augmented_writer(args.output, source->sensor_size()));
    } catch (const std::exception& e) {
      return output_fault_exit("run", e.what());
    }
  }
  // -q: nothing to count (and no per-pixel counts to allocate).
  CountingSink counting_sink(writer_sink.get(), args.quiet ? std::nullopt : std::optional(source->sensor_size()));
  engine::AugmentedSink* const sink =
      args.quiet ? static_cast<engine::AugmentedSink*>(writer_sink.get()) : &counting_sink;

  const bool rendering = !args.frames_dir.empty() || !args.video.empty() || args.window;
  if (rendering) args.engine.render_batches = 16;
  std::optional<engine::Engine> eng;
  std::unique_ptr<engine::RenderStage> render_stage;
  try {
    eng.emplace(*source, sink, args.engine);
    if (rendering) {
      if (!frame_sink) {  // the on-screen window: it stops the engine when closed
        engine::Engine* running = &*eng;
        frame_sink = std::make_unique<WindowFrameSink>(
            "evlife: " + source->describe(), [running] { running->request_stop(); });
      }
      render_stage = std::make_unique<engine::RenderStage>(*eng->pipeline().state().render_tap,
                                                           source->sensor_size(), args.render,
                                                           *frame_sink);
      eng->pipeline().attach(*render_stage);
    }
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "evlife run: %s: %s\n", source->describe().c_str(), e.what());
    return kExitUsage;
  } catch (const std::runtime_error& e) {
    std::fprintf(stderr, "evlife run: output error: %s\n", e.what());
    return kExitOutput;
  }
  const auto wall_start = std::chrono::steady_clock::now();
  g_engine.store(&*eng);
  const engine::RunResult result = [&] {
    const StopSignals stop_signals(on_run_signal);  // the setup's flag, checked after: no signal is lost
    if (stop.requested()) eng->request_stop();
    return eng->run();
  }();
  g_engine.store(nullptr);
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();

  if (!args.quiet && result.status != engine::RunStatus::realtime_error) {
    print_run_summary(args, *source, result, render_stage.get(), wall_s);
    counting_sink.print(stdout);
  }
  if (result.status == engine::RunStatus::completed && result.stats.events_in == 0)  // as process
    warn_empty_crop("run", std::string(file_of_source(args.source)), args.input_options);
  if (frame_sink) warn_earlier_frames("run", args.frames_dir, frame_sink->earlier_frames_left());
  // Times the camera's decoder changed are named whatever -q says (never a silent change).
  if (const auto* camera = dynamic_cast<const engine::Dvs128Source*>(source.get())) {
    if (const std::uint64_t n = camera->decoder_counters().time_regressions; n > 0) {
      std::fprintf(stderr, "evlife run: warning: %llu events of %s came earlier than the event before them (a word "
                   "lost or corrupt on the way) and were stamped with its time\n",
                   static_cast<unsigned long long>(n), source->describe().c_str());
    }
  }
  if (render_stage && result.status == engine::RunStatus::completed && result.stats.has_time_range) {
    const auto& stats = result.stats;
    const std::uint64_t read_us = span_us(stats.first_t_us, stats.last_t_us);
    const auto& at = args.render.at_us;  // from the first event (never negative), as the span
    const auto late =
        std::count_if(at.begin(), at.end(), [&](std::int64_t t) { return static_cast<std::uint64_t>(t) > read_us; });
    warn_instants_after_end("run", static_cast<std::size_t>(late), stats.first_t_us, stats.last_t_us,
                            InstantsOrigin::events_read);
  }
  return run_exit_status(result, render_stage.get(), args.quiet);
}

}  // namespace

EVLIFE_REGISTER_COMMAND("run", "real-time multithreaded engine: live camera or paced replay",
                        run_engine);

}  // namespace evlife::cli::run_command
