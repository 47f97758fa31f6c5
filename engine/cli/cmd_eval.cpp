// `evlife eval INPUT -o DIR`: the paper's evaluation (Figs. 9, 10) as plots
// and CSVs, velocity histograms, and a sharpness comparison of the lifetime
// rendering against 1 ms / 30 ms fixed windows, with a one-page summary.html.
// Raw input is processed once per estimator variant (N = 3, 5, 7, with and
// without regularization); every pass streams (constant memory).
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


#include "arg_parser.h"
#include "command_start.h"
#include "command.h"
#include "evlife/config/config.h"
#include "evlife/io/event_reader.h"
#include "evlife/io/output_path.h"
#include "evlife/io/stream_copy_name.h"
#include "evlife/render/evaluation.h"
#include "evlife/render/augmented_source.h"
#include "evlife/render/fixed_window_map.h"
#include "evlife/render/frame_composer.h"
#include "evlife/render/frame_painter.h"
#include "evlife/render/histogram.h"
#include "evlife/render/image_quality.h"
#include "evlife/render/media.h"
#include "evlife/render/plot.h"
#include "evlife/render/render_cursor.h"
#include "evlife/render/sharpness.h"
#include "exit_code.h"
#include "stop_signals.h"
#include "input_spool.h"

namespace evlife::cli::eval_command {
namespace {

namespace fs = std::filesystem;

constexpr OptionSpec kEvalOptions[] = {
    {"output", 'o', true, false},    {"sensor", 0, true, false},  kConfigOptionSpec,
    kSetOptionSpec, kPrintConfigOptionSpec, kInputOptionSpec,
    {"sample-every", 0, true, false}, {"frame-at", 0, true, false, "at"},
    {"quiet", 'q', false, false},    {"help", 'h', false, false},
    kTopicOptionSpec, kTimeUnitOptionSpec, kPolarityOptionSpec, kFromOptionSpec, kToOptionSpec,
};

void print_eval_help(std::FILE* out) {
  std::fprintf(out,
      "evlife eval — the paper's evaluation of a recording, as plots, CSVs and a summary page\n"
      "\n"
      "Usage: evlife eval INPUT -o DIR [--sample-every DUR] [--frame-at T] [--sensor WxH]\n"
      "                   [--config FILE] [--set KEY=VALUE]... [--quiet]\n"
      "\n"
      "Writes into DIR (created):\n"
      "  summary.html               one page with every figure and the key numbers\n"
      "  lifetime_histogram.png/.csv  lifetimes in 0.2 ms bins, N=5 with and without\n"
      "                             regularization (paper Fig. 10); noise excluded\n"
      "  prediction_error_cdf.png/.csv  share of predictions with |t - t_predicted| below x,\n"
      "                             N = 3, 5, 7 with and without regularization (paper Fig. 9)\n"
      "  velocity_histogram.png/.csv  speed |v| of non-noise events (px/s)\n"
      "  velocity_components.png/.csv vx and vy of non-noise events (px/s)\n"
      "  sharpness.png/.csv, sharpness_summary.csv  thin-edge share, completeness and their\n"
      "                             product of the lifetime image vs 1, 10 and 30 ms\n"
      "                             windows, sampled every --sample-every\n"
      "  runs.csv                   per estimator run: events, share with a lifetime, with a\n"
      "                             prediction, median |prediction error| / lifetime, timings\n"
      "  compare_frame.png          1 ms | 30 ms | lifetime at --frame-at\n"
      "The CSVs are RFC 4180 CSV with a header line: run names hold a comma and are\n"
      "quoted (\"N=5, regularized\"); a histogram's last line, a '#' comment, counts\n"
      "the values below its first bin / above its last per column. In Python:\n"
      "pandas.read_csv(F, comment='#'), or csv.reader skipping lines that start '#'.\n"
      "\n"
      "INPUT  a raw recording (processed 6 times: N = 3, 5, 7 x regularization on/off,\n"
      "       the rest of the configuration from --config/--set; the configured N and\n"
      "       regularization give the sharpness and the compare frame), or an augmented\n"
      "       .bin/.csv/.h5 from `evlife process` (one run: its lifetimes as they are).\n"
      "\n"
      "Sharpness: in each image (active events, or all events of a fixed window), a pixel\n"
      "lies on an edge when a run of >= 3 active pixels passes through it (horizontally,\n"
      "vertically or diagonally), on a thin edge when in addition its horizontal or\n"
      "vertical run is <= 2 px. thin-edge share = thin-edge pixels / active pixels (higher\n"
      "= sharper, less noise); mean thickness over edge pixels (lower = sharper).\n"
      "Completeness: the share of the edge pixels of the best fixed window at that instant\n"
      "(the one with the most thin-edge pixels) that an image draws within 1 px. A method\n"
      "is complete *and* sharp when completeness x thin-edge share is high.\n"
      "\n"
      "Options:\n"
      "  -o, --output DIR       required.\n"
      "  --sample-every DUR     sharpness sampling period (default 50ms, at least 1ms).\n"
      "                         Instants where no fixed window draws a pixel (a pause of\n"
      "                         the recording) are counted, not sampled; where no window\n"
      "                         shows an edge, completeness (and the score) is n/a.\n"
      "  -i, --input FILE       the INPUT (also as the first argument).\n"
      "  --frame-at T, --at T   instant of compare_frame.png, seconds from the first event\n"
      "                         (default 0.5; the last event if the recording is shorter;\n"
      "                         with --from, from the first event read).\n"
      "  --sensor WxH           sensor size when the input does not state it.\n"
      );
  std::fputs((std::string(kInputOptionsHelp) + std::string(kCropOptionsHelp)).c_str(), out);
  std::fprintf(out,
      "  -q, --quiet            no progress and no summary on stdout.\n");
  std::fputs(config_options_help().c_str(), out);
  std::fprintf(out,
      "\n"
      "Exit status: 0 done; 2 bad command line; 3 input error; 4 output error;\n"
      "             130 interrupted (nothing written).\n"
      "\n"
      "Example:\n"
      "  evlife eval stripes.mat -o eval_stripes && xdg-open eval_stripes/summary.html\n");
}

struct EvalArgs : CommonArgs {
  std::string output;
  std::int64_t sample_every_us = 50000;
  std::int64_t frame_at_us = 500000;
  bool frame_at_given = false;
};

EvalArgs parse_eval_args(int argc, char** argv) {
  const ParsedArgs a = parse_args(argc, argv, kEvalOptions);
  EvalArgs e;
  if (!parse_common_args(a, e)) return e;
  refuse_selection_of_augmented(e.input_options, e.input);
  refuse_estimator_settings_for_augmented("eval", e, a.values("set"));
  // A setting valid for the configured N only stopped eval half-way, as an
  // input error, with nothing written. (evlife's output is not re-estimated.)
  if (const std::string refusal = render::eval::comparison_runs_refusal(e.config.config.estimator);
      !refusal.empty() && !is_evlife_output(e.input))
    throw UsageError(refusal);
  const auto out = a.value("output");
  if (!out) throw UsageError("missing -o DIR");
  if (out->empty())  // (it was taken for the folder "": exit 4 "cannot create directory ")
    throw UsageError("-o is empty: give the folder the report is written into");
  e.output = *out;
  // The report written over its input, refused before any work (the writers check each file again).
  for (const std::string& name : render::eval::report_file_names()) {
    if (const auto refusal = io::output_overwrites_input(e.input, (std::filesystem::path(e.output) / name).string()))
      throw UsageError(*refusal);
  }
  if (const auto s = a.value("sample-every")) e.sample_every_us = parse_time_flag("sample-every", *s);
  if (const auto s = a.value("frame-at")) {
    e.frame_at_us = parse_time_flag(a.typed_name("frame-at"), *s);  // --at or --frame-at, as typed
    e.frame_at_given = true;
  }
  if (e.sample_every_us < 1000) throw UsageError("--sample-every must be at least 1ms");
  return e;
}

int eval_recording(int argc, char** argv) {
  EvalArgs args;
  if (const auto done = start_command("eval", argc, argv, print_eval_help, [&] { args = parse_eval_args(argc, argv); })) {
    return *done;
  }
  std::optional<InputSpool> spool;  // INPUT `-` or a pipe: read from a copy
  if (const auto done = spool_stream_input("eval", args.input, args.quiet, spool)) return *done;
  if (args.print_config) {
    print_config(args.config, args.sensor);
    return kExitOk;
  }
  std::error_code ec;
  fs::create_directories(args.output, ec);
  if (ec || !fs::is_directory(args.output)) {  // why, as render's and run's frame folders say it
    std::fprintf(stderr, "evlife eval: output error: cannot create directory %s: %s\n", args.output.c_str(),
                 ec ? ec.message().c_str() : "not a directory");
    return kExitOutput;
  }
  render::eval::EvaluationOptions options;
  options.input = args.input;
  options.output = args.output;
  options.sensor = user_sensor_size(args.sensor, args.config);
  options.input_options = args.input_options;
  options.estimator = args.config.config.estimator;
  options.sample_every_us = args.sample_every_us;
  options.frame_at_us = args.frame_at_us;
  options.frame_at_given = args.frame_at_given;
  options.quiet = args.quiet;
  render::eval::Evaluation evaluation;
  try {
    const StopRequest stop;
    options.stop = stop.flag();
    evaluation = render::eval::evaluate(options);
  } catch (const render::eval::EvaluationStopped&) {
    std::fprintf(stderr, "evlife eval: interrupted: nothing written to %s (the report needs every run to the end)\n",
                 args.output.c_str());
    return kExitInterrupted;
  } catch (const io::ReadError& e) {
    return open_fault_exit("eval", args.input, e);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "evlife eval: %s: %s\n", io::name_in_messages(args.input).c_str(), e.what());
    return kExitInput;
  }
  warn_user_sensor_ignored("eval", args.sensor, args.config, args.input, evaluation.sensor);
  if (!evaluation.runs.empty() && evaluation.runs[evaluation.primary_index].events == 0 && !evaluation.input_fault) {
    std::fprintf(stderr, "evlife eval: warning: %s: the report's figures are empty\n",
                 no_event_text(args.input, args.input_options).c_str());
  }
  try {
    render::eval::write_evaluation(options, evaluation);
  } catch (const render::eval::EvaluationOutputError& e) {
    std::fprintf(stderr, "evlife eval: output error: %s\n", e.what());
    return kExitOutput;
  }
  if (!args.quiet) render::eval::print_evaluation_summary(stdout, options, evaluation);
  if (evaluation.input_fault) {
    std::fprintf(stderr,
                 "evlife eval: input error: %s\n"
                 "evlife eval: %s holds the evaluation of the %llu events before the fault\n",
                 evaluation.input_fault->what(), args.output.c_str(),
                 static_cast<unsigned long long>(evaluation.runs[evaluation.primary_index].events));
    return kExitInput;
  }
  return kExitOk;
}

}  // namespace

EVLIFE_REGISTER_COMMAND("eval", "the paper's evaluation plots (Figs. 9, 10), velocity and sharpness", eval_recording);

}  // namespace evlife::cli::eval_command
