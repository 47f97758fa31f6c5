// `evlife process INPUT -o OUT.csv|OUT.bin|OUT.h5`: every event of a recording gets
// its lifetime and velocity. Streams batch by batch (constant memory); on bad
// input writes and flushes everything before the fault, then exits non-zero.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "arg_parser.h"
#include "command_start.h"
#include "command.h"
#include "memory_check.h"
#include "stop_signals.h"
#include "evlife/algo/lifetime_estimator.h"
#include "evlife/config/config.h"
#include "evlife/engine/prefetch_reader.h"
#include "evlife/engine/process_stream.h"
#include "evlife/engine/write_behind_writer.h"
#include "evlife/io/augmented_event_writer.h"
#include "evlife/io/event_reader.h"
#include "evlife/io/output_path.h"
#include "evlife/io/sensor_size_from_data.h"
#include "evlife/io/stream_copy_name.h"
#include "exit_code.h"
#include "input_spool.h"
#include "lifetime_summary.h"
#include "progress_meter.h"

namespace evlife::cli::process_command {
namespace {

constexpr std::size_t kBatchEvents = 1 << 16;  // 1 MiB in, 2 MiB out

constexpr OptionSpec kOptions[] = {
    {"output", 'o', true, false},     {"sensor", 0, true, false},
    kConfigOptionSpec, kSetOptionSpec, kPrintConfigOptionSpec, kInputOptionSpec,
    {"quiet", 'q', false, false},     {"one-thread", 0, false, false},
    {"help", 'h', false, false},      kTopicOptionSpec, kTimeUnitOptionSpec, kPolarityOptionSpec, kFromOptionSpec, kToOptionSpec,
};

void print_help(std::FILE* out) {
  std::fprintf(out,
      "evlife process — give every event of a recording its lifetime and velocity\n"
      "\n"
      "Usage: evlife process INPUT -o OUTPUT.csv|.bin|.h5 [--sensor WxH]\n"
      "                      [--config FILE] [--set KEY=VALUE]... [--quiet] [--one-thread]\n"
      "\n"
      "For each event, fits a plane to the recent events around it (RANSAC, then a\n"
      "least-squares refit regularized by the previous prediction; Mueggler et al.,\n"
      "ICRA 2015) and writes the event with its lifetime (time the edge needs to move\n"
      "one pixel), its velocity and the error of the prediction made for it. Events\n"
      "without enough support are labelled noise (lifetime 0, velocity 0). One output\n"
      "row per input event, in input order, input fields unchanged.\n"
      "\n"
      "INPUT formats (sniffed from the content, else the extension):\n");
  for (const auto& f : io::known_event_formats()) {
    std::fprintf(out, "  %-14.*s %.*s\n", static_cast<int>(f.name.size()), f.name.data(),
                 static_cast<int>(f.description.size()), f.description.data());
  }
  std::fprintf(out,
      "\n"
      "Options:\n"
      "  -o, --output FILE  required. FILE.csv: header x,y,t,p,lifetime,vx,vy,prediction_error\n"
      "                     (t, lifetime, prediction_error in µs; vx, vy in px/s; p 1/-1;\n"
      "                     prediction_error empty when there was none). FILE.bin: compact\n"
      "                     binary, 32 bytes per event (see README). FILE.h5: HDF5, one\n"
      "                     dataset per column (x, y, t, p, lifetime, vx, vy,\n"
      "                     prediction_error), for Python (h5py).\n"
      "  -i, --input FILE   the INPUT (also as the first argument).\n"
      "  --sensor WxH       sensor size in pixels, e.g. 240x180. Used when the format does\n"
      "                     not state one (the format wins). Without it: estimator.sensor.*\n"
      "                     if you set it, else the smallest sensor holding every event\n"
      "                     (one extra pass over the file).\n"
      "%s"
      "  --config FILE      YAML configuration; keys it omits keep the built-in defaults.\n"
      "                     Without it: %s\n"
      "                     if present (documents every key, unit and range), else the\n"
      "                     built-in defaults (the same values). Presets beside it:\n"
      "                     dim-light.yaml (a slow photoreceptor, latency jitter of\n"
      "                     hundreds of us: fewer lifetimes, none far off),\n"
      "                     faint-texture.yaml (faint texture on a quiet sensor: at most\n"
      "                     ~1 Hz/px of background activity). README and\n"
      "                     algo/README.md explain both.\n"
      "  --set KEY=VALUE    override one key after --config, repeatable, e.g.\n"
      "                     --set estimator.window_size=7 --set estimator.regularization=false\n"
      "  --print-config     print the effective configuration as YAML and exit.\n"
      "  -q, --quiet        no progress and no summary (errors are still printed).\n"
      "  --one-thread       decode, estimate and write on one thread. By default the\n"
      "                     file is decoded ahead and the output written behind, each on\n"
      "                     a thread of its own, while the estimator works: the same\n"
      "                     output, sooner where decoding or writing costs (CSV, HDF5).\n"
      "  -h, --help         this text.\n"
      "\n"
      "Progress goes to stderr (a live line on a terminal, else a line every 10 s);\n"
      "the summary to stdout: events, share labelled noise, lifetime percentiles,\n"
      "share with a prediction and median |prediction error|, wall time, events/s;\n"
      "for a short recording its length in median lifetimes (warm-up), and over\n"
      "0.5 s or more the pixels firing at 100 Hz or more (hot pixels, or busy edges).\n"
      "\n"
      "Bad input (missing file, unknown format, truncated or corrupt data, coordinates\n"
      "outside the sensor, timestamps going backwards) stops the run with a message\n"
      "naming the file and the event index / byte offset; the events before the fault\n"
      "are written and flushed.\n"
      "\n"
      "Exit status: 0 done; 2 bad command line or configuration; 3 input error;\n"
      "             4 output error; 130 interrupted (output flushed up to the stop).\n"
      "\n"
      "Examples:\n"
      "  evlife process stripes.mat -o stripes.csv\n"
      "  evlife process events.txt --sensor 240x180 -o events.bin --set estimator.window_size=7\n",
      (std::string(kInputOptionsHelp) + std::string(kCropOptionsHelp)).c_str(),
      config::default_config_path().empty() ? "(no default file compiled in)"
                                            : config::default_config_path().c_str());
}

// Everything a run needs, resolved from the command line before any work.
struct ProcessArgs : CommonArgs {
  std::string output;
  bool one_thread = false;
};

ProcessArgs parse_process_args(int argc, char** argv) {
  const ParsedArgs a = parse_args(argc, argv, kOptions);
  ProcessArgs p;
  if (!parse_common_args(a, p)) return p;
  const auto out = a.value("output");
  if (!out) throw UsageError("missing -o OUTPUT (a .csv, .bin or .h5 file)");
  p.output = *out;
  p.one_thread = a.has("one-thread");
  if (!io::names_an_augmented_output(p.output)) {
    throw UsageError("-o " + p.output + ": the output must end in .csv, .bin or .h5");
  }
  if (const auto refusal = io::output_overwrites_input(p.input, p.output)) throw UsageError("-o " + *refusal);
  return p;
}

struct ResolvedSensor {
  SensorSize size;
  std::string source;
};

ResolvedSensor resolve_sensor(const ProcessArgs& args, const config::Config& cfg,
                              const io::EventReader& probe, const StopRequest& stop) {
  if (const auto s = io::stated_sensor_size(probe, args.sensor)) {
    warn_user_sensor_ignored("process", args.sensor, args.config, args.input, *s);
    if (const std::string guessed = probe.sensor_size_note(); !guessed.empty()) return {*s, guessed};
    return {*s, "stated by the " + std::string(probe.format_name()) + " file"};
  }
  if (args.sensor) return {*args.sensor, "--sensor"};
  if (const auto* o = args.config.builder.user_origin_of_input_keys()) {
    return {cfg.estimator.sensor, "estimator.sensor (" + o->where + ")"};
  }
  if (!args.quiet) {
    std::error_code ec;
    if (std::filesystem::file_size(args.input, ec) > (std::uintmax_t{64} << 20) && !ec) {
      std::fprintf(stderr, "evlife process: %s states no sensor size: scanning the data for it "
                   "(pass --sensor WxH to skip this pass)\n", io::name_in_messages(args.input).c_str());
    }
  }
  // Smallest sensor holding every event; a fault after some events leaves
  // those (the main pass writes them, then reports it); a file with no event
  // to scan is an input error here (nothing to write), as for render and run.
  const SensorSize scanned = io::sensor_size_from_data(args.input, args.input_options, stop.flag());
  if (stop.requested()) return {scanned, "the scan's, interrupted"};  // the main pass stops at once
  // No event camera is this large: most likely a stray event sets the size
  // (and the estimator's memory, ~41 bytes per pixel and polarity).
  constexpr int kLargestKnownSide = 2048;
  if (scanned.width > kLargestKnownSide || scanned.height > kLargestKnownSide) {
    std::fprintf(stderr, "evlife process: warning: the events of %s span %dx%d pixels; if the sensor is smaller, "
                 "pass --sensor WxH: an event outside it is then reported with its index\n",
                 io::name_in_messages(args.input).c_str(), scanned.width, scanned.height);
  }
  return {scanned, "scanned from the data"};
}

void print_summary(const ProcessArgs& args, const io::EventReader& reader,
                   const ResolvedSensor& sensor, const LifetimeEstimator& estimator,
                   const LifetimeSummary& summary, const engine::ProcessStreamResult& result,
                   double wall_s) {
  std::fprintf(stdout, "evlife process: %s -> %s\n", io::name_in_messages(args.input).c_str(), args.output.c_str());
  std::fprintf(stdout, "  input               %.*s, sensor %dx%d (%s)\n",
               static_cast<int>(reader.format_name().size()), reader.format_name().data(),
               sensor.size.width, sensor.size.height, sensor.source.c_str());
  std::fprintf(stdout, "  configuration       %s\n", args.config.describe().c_str());
  if (args.input_options.polarity != io::PolarityFilter::both) {
    std::fprintf(stdout, "  polarity            %s events only (--polarity): the others were not read\n",
                 args.input_options.polarity == io::PolarityFilter::on ? "ON" : "OFF");
  }
  summary.print(stdout, wall_s, result.estimator_s);
  if (result.input_fault || result.output_fault || result.stopped) {
    std::fprintf(stdout, "  stopped early       %s (see the message below)\n",
                 result.input_fault ? "input error" : result.output_fault ? "output error" : "interrupted");
  }
  if (reader.skipped_record_count() > 0)
    std::fprintf(stdout, "  skipped records     %s\n", io::skipped_records_text(reader).c_str());
  const LifetimeStats& st = estimator.stats();
  if (st.noise > st.rejected()) {
    std::fprintf(stdout, "  why noise           %llu few past events, %llu no plane with support, %llu fit unresolved\n",
                 static_cast<unsigned long long>(st.noise_few_samples),
                 static_cast<unsigned long long>(st.noise_unsupported),
                 static_cast<unsigned long long>(st.noise_unresolved));
  }
  if (st.rejected() > 0) std::fprintf(stdout, "  rejected            %s\n", rejected_events_text(st).c_str());
  std::fflush(stdout);
}

int exit_status(const ProcessArgs& args, const engine::ProcessStreamResult& result) {
  const unsigned long long written = result.events_written;
  if (result.output_fault) {
    return output_fault_exit("process", *result.output_fault, " (" + std::to_string(written) + " events processed before it)");
  }
  if (result.input_fault) {
    std::fprintf(stderr,
                 "evlife process: input error: %s\n"
                 "evlife process: the %llu events before the fault were written to %s\n",
                 result.input_fault->c_str(), written, args.output.c_str());
    return kExitInput;
  }
  if (result.stopped) {
    std::fprintf(stderr, "evlife process: interrupted; the first %llu events were written to %s\n",
                 written, args.output.c_str());
    return kExitInterrupted;
  }
  return kExitOk;
}


int process_recording(int argc, char** argv) {
  const auto wall_start = std::chrono::steady_clock::now();
  ProcessArgs args;
  config::Config cfg;
  if (const auto done = start_command("process", argc, argv, print_help, [&] {
        args = parse_process_args(argc, argv);
        cfg = args.config.config;
      })) {
    return *done;
  }
  if (args.print_config) {
    print_config(args.config, args.sensor);
    return kExitOk;
  }
  std::optional<InputSpool> spool;  // INPUT `-` or a pipe: read from a copy
  if (const auto done = spool_stream_input("process", args.input, args.quiet, spool)) return *done;

  // Input: sniff the format, settle the sensor, then open the checked reader
  // (bounds and time order) for that sensor.
  // From the scan for a sensor size on, a stop signal ends the command with
  // what it wrote: an output of no event when it comes before the main pass.
  const StopRequest stop;
  std::unique_ptr<io::EventReader> reader;
  ResolvedSensor sensor;
  try {
    const auto probe = io::open_unchecked_event_reader(args.input, args.input_options);
    sensor = resolve_sensor(args, cfg, *probe, stop);
    io::ReaderOptions checked = args.input_options;
    checked.sensor = sensor.size;
    reader = io::open_event_reader(args.input, checked);
  } catch (const io::ReadError& e) {
    return open_fault_exit("process", args.input, e);
  }
  cfg.estimator.sensor = sensor.size;
  if (const auto refusal = estimator_memory_refusal(sensor.size, 1)) {
    std::fprintf(stderr, "evlife process: %s: %s (sensor: %s)\n", io::name_in_messages(args.input).c_str(), refusal->c_str(),
                 sensor.source.c_str());
    return kExitInput;
  }
  std::optional<LifetimeEstimator> estimator;
  try {
    estimator.emplace(cfg.estimator);
  } catch (const std::invalid_argument& e) {
    // (A scanned sensor this large got resolve_sensor's warning, which says what to do.)
    std::fprintf(stderr, "evlife process: %s: sensor %dx%d (%s) is not usable: %s\n",
                 io::name_in_messages(args.input).c_str(), sensor.size.width, sensor.size.height, sensor.source.c_str(),
                 e.what());
    return kExitInput;
  }

  std::unique_ptr<io::AugmentedEventWriter> writer;
  try {
    writer = io::open_augmented_writer(args.output, sensor.size);
  } catch (const io::WriteError& e) {
    return output_fault_exit("process", e.what());
  }

  if (!args.one_thread) {  // the same events in, the same bytes out: only sooner
    reader = std::make_unique<engine::PrefetchReader>(std::move(reader));
    writer = std::make_unique<engine::WriteBehindWriter>(std::move(writer));
  }

  std::error_code size_ec;
  const auto input_bytes = std::filesystem::file_size(args.input, size_ec);
  ProgressMeter progress("evlife process", size_ec ? 0 : static_cast<std::int64_t>(input_bytes),
                         [&] { return static_cast<std::int64_t>(reader->bytes_consumed()); });
  progress.set_enabled(!args.quiet);
  LifetimeSummary summary(sensor.size);
  const engine::ProcessStreamResult result = [&] {
    return engine::process_stream(
        *reader, *estimator, *writer,
        [&](std::span<const AugmentedEvent> batch) {
          summary.add(batch);
          progress.update(summary.events());
        },
        stop.flag(), kBatchEvents);
  }();
  progress.finish();
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();

  if (!args.quiet) print_summary(args, *reader, sensor, *estimator, summary, result, wall_s);
  if (summary.events() == 0 && !result.input_fault && !result.stopped) warn_empty_crop("process", args.input, args.input_options);
  return exit_status(args, result);
}

}  // namespace

EVLIFE_REGISTER_COMMAND("process", "give every event of a recording its lifetime and velocity",
                        process_recording);

}  // namespace evlife::cli::process_command
