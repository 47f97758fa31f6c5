// `evlife render INPUT -o DIR|VIDEO`: images of the events active at chosen
// instants (paper Figs. 1, 8, 13, 14), optionally beside fixed-window images.
// One forward pass over the recording: frames are drawn at increasing times
// from the incrementally fed active-event set, never by re-reading history.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>


#include <fmt/format.h>

#include "arg_parser.h"
#include "command_start.h"
#include "command.h"
#include "earlier_frames_warning.h"
#include "instants_after_end_warning.h"
#include "stop_signals.h"
#include "video_flag.h"
#include "evlife/config/config.h"
#include "evlife/io/event_reader.h"
#include "evlife/io/output_path.h"
#include "evlife/io/stream_copy_name.h"
#include "evlife/render/active_event_set.h"
#include "evlife/render/augmented_source.h"
#include "evlife/render/fixed_window_map.h"
#include "evlife/render/frame_clock.h"
#include "evlife/render/frame_composer.h"
#include "evlife/render/frame_memory.h"
#include "evlife/render/frame_sink.h"
#include "evlife/render/media.h"
#include "evlife/render/output_kind.h"
#include "evlife/render/render_cursor.h"
#include "evlife/render/render_recording.h"
#include "exit_code.h"
#include "input_spool.h"
#include "lifetime_summary.h"

namespace evlife::cli::render_command {
namespace {

constexpr OptionSpec kRenderOptions[] = {
    {"output", 'o', true, false},  {"frames", 0, true, false}, {"video", 0, true, false}, {"at", 0, true, false},
    {"fps", 0, true, false, "render-fps"},
    {"from", 0, true, false},      {"to", 0, true, false},          {"mode", 'm', true, false, "render-mode"},
    {"color", 0, true, false},     {"scale", 0, true, false},       {"no-caption", 0, false, false},
    {"no-legend", 0, false, false}, {"no-thinning", 0, false, false}, {"lifetime-range", 0, true, false},
    {"video-fps", 0, true, false}, {"sensor", 0, true, false},      kConfigOptionSpec,
    kSetOptionSpec, kPrintConfigOptionSpec, kInputOptionSpec,
    {"quiet", 'q', false, false},    {"help", 'h', false, false},
    kTopicOptionSpec, kTimeUnitOptionSpec, kPolarityOptionSpec,
};

void print_render_help(std::FILE* out) {
  std::fprintf(out,
      "evlife render — draw the events active at any instant (sharp edges, paper Figs. 1, 8)\n"
      "\n"
      "Usage: evlife render INPUT -o DIR|FRAME.png|OUT.mp4|OUT.avi\n"
      "                     [--at T1,T2,...] | [--fps F [--from T0] [--to T1]]\n"
      "                     [--mode lifetime|window:DUR|compare] [--color lifetime|polarity|plain]\n"
      "                     [--scale K] [--no-caption] [--no-legend] [--no-thinning]\n"
      "                     [--lifetime-range MIN:MAX] [--video-fps F] [--sensor WxH]\n"
      "                     [--config FILE] [--set KEY=VALUE]... [--quiet]\n"
      "\n"
      "An event is drawn from its timestamp until timestamp + lifetime; per pixel the\n"
      "newest event wins; noise (lifetime 0) is never drawn; edge thinning (paper\n"
      "III-B.3) expires the pixel an edge has just left, so accelerating edges stay thin.\n"
      "\n"
      "INPUT  an augmented file from `evlife process` (.bin/.csv/.h5: lifetimes used as\n"
      "       they are) or any raw recording `evlife process` reads (processed on the fly by the\n"
      "       estimator; --config/--set as for `evlife process`).\n"
      "\n"
      "Options:\n"
      "  -o, --output PATH   required. A directory (created) for PNG frames named\n"
      "                      frame_NNNNNN_tSECONDS.png; FILE.png for one --at instant; or a\n"
      "                      video: .mp4 (codec mp4v) or .avi (codec MJPG), via OpenCV.\n"
      "  --frames DIR        as in `evlife run`: a folder of PNG frames, whatever its name.\n"
      "  --video FILE        as in `evlife run`: a video, FILE ending in .mp4 or .avi.\n"
      "  -i, --input FILE    the INPUT (also as the first argument).\n"
      "  --at T1,T2,...      instants to draw, seconds from the first event (any value,\n"
      "                      not only frame multiples; e.g. 0.25,0.5,1.0 or 250ms,1s).\n"
      "                      Drawn in increasing order in one pass, each once.\n"
      "  --fps F             draw F frames per second of recording time (default 30 when\n"
      "                      --at is not given), from --from (default 0) to --to (default:\n"
      "                      the last event).\n"
      "  -m, --mode M        lifetime (default): the active events. (--render-mode and\n"
      "                      --render-fps, as `evlife run` spelled them, are accepted.)\n"
      "                      window:DUR: every event of the fixed window [t-DUR, t], e.g.\n"
      "                      window:30ms (the naive method; DUR up to 536 s).\n"
      "                      compare: 1 ms window | 30 ms window | lifetime, side by side,\n"
      "                      labelled as in the paper.\n"
      "  --color C           lifetime (default; blue = short, red = long, log scale, with\n"
      "                      a legend), polarity (ON green, OFF magenta) or plain (white).\n"
      "                      Fixed windows have no lifetime: drawn plain (or by polarity).\n"
      "  --scale K           integer upscaling 1..32 (default: 512 / larger sensor side,\n"
      "                      at least 1: x4 for a 128x128 DVS).\n"
      "  --lifetime-range MIN:MAX  colour scale in ms (default 0.3:30).\n"
      "  --no-caption        no 'time / mode' line under the frame.\n"
      "  --no-legend         no lifetime colour bar.\n"
      "  --no-thinning       disable edge thinning (to see what it does).\n"
      "  --video-fps F       frame rate written into a video, within [0.01, 60]\n"
      "                      (default: --fps, i.e. real time, up to 60: slow motion\n"
      "                      beyond; 10 with --at). The summary says the rate used.\n"
      "  --sensor WxH        sensor size when the input does not state it.\n"
      );
  std::fputs(std::string(kInputOptionsHelp).c_str(), out);
  std::fprintf(out,
      "  -q, --quiet         no progress and no summary.\n");
  std::fputs(config_options_help().c_str(), out);
  std::fprintf(out,
      "\n"
      "Progress (frames, recording time) goes to stderr; the summary to stdout.\n"
      "Exit status: 0 done; 2 bad command line; 3 input error (frames drawn before the\n"
      "fault are kept, a video is closed properly); 4 output error; 130 interrupted.\n"
      "\n"
      "Examples:\n"
      "  evlife render stripes.mat -o frames/ --at 0.25,0.5,1.0 --mode compare\n"
      "  evlife render stripes.mat -o compare.png --at 0.5 --mode compare\n"
      "  evlife render stripes.mat -o stripes.mp4 --fps 100 --video-fps 25 --mode compare\n"
      "  evlife render augmented.bin -o frames/ --fps 60 --from 0.2 --to 0.4\n");
}

struct RenderArgs : CommonArgs {
  render::RecordingRenderOptions job;  // what to draw and where
};

double parse_positive(const std::string& option, const std::string& text, double max) {
  // One message for every value outside (0, max], zero and negatives alike.
  const auto v = parse_decimal(text);
  if (!v || !(*v > 0.0 && *v <= max))
    throw UsageError("--" + option + " " + text + ": expected a number in (0, " + std::to_string(static_cast<long long>(max)) + "]");
  return *v;
}

RenderArgs parse_render_args(int argc, char** argv) {
  const ParsedArgs a = parse_args(argc, argv, kRenderOptions);
  RenderArgs r;
  if (!parse_common_args(a, r, /*crop=*/false)) return r;  // --from/--to: the frames drawn
  refuse_selection_of_augmented(r.input_options, r.input);
  refuse_estimator_settings_for_augmented("render", r, a.values("set"));
  const auto out = a.value("output"), frames = a.value("frames"), video = a.value("video");
  if (int{out.has_value()} + int{frames.has_value()} + int{video.has_value()} > 1)
    throw UsageError("-o, --frames and --video each name the output: give one");
  if (!out && !frames && !video) throw UsageError("missing -o DIR|OUT.mp4|OUT.avi");
  r.job.output = out ? *out : frames ? *frames : *video;
  if (r.job.output.empty())  // (it was taken for the folder "": exit 4 "cannot create directory : Invalid argument")
    throw UsageError("the output (-o, --frames or --video) is empty: give a folder (PNG frames), FILE.png, "
                     "OUT.mp4 or OUT.avi");
  // -o by its extension; --frames and --video as `evlife run` takes them.
  const render::OutputKind kind = frames ? render::OutputKind::frames_folder : render::output_kind(r.job.output);
  if (video && kind != render::OutputKind::video) throw UsageError(video_flag_refusal(*video));
  if (kind == render::OutputKind::unsupported)
    throw UsageError("-o " + r.job.output + ": use a directory (PNG frames), FILE.png (one --at instant), .mp4 or .avi");
  r.job.video = kind == render::OutputKind::video;
  r.job.single_png = kind == render::OutputKind::single_png;
  r.job.input = r.input;
  if (const auto refusal = io::output_overwrites_input(r.input, r.job.output)) throw UsageError("-o " + *refusal);
  if (a.has("at") && (a.has("fps") || a.has("from") || a.has("to"))) {
    throw UsageError("--at cannot be combined with --fps/--from/--to");
  }
  if (const auto at = a.value("at")) r.job.at_us = parse_instants_us("at", *at, "render");
  if (r.job.single_png && r.job.at_us.size() != 1) {
    throw UsageError("-o " + r.job.output + ": a single PNG needs exactly one --at instant (use a directory for more)");
  }
  if (const auto f = a.value("fps")) r.job.fps = parse_number<double>("fps", *f, render::kMinFps, 1e6);
  if (const auto f = a.value("from")) r.job.from_us = parse_time_flag("from", *f);
  if (const auto f = a.value("to")) {
    r.job.to_us = parse_time_flag("to", *f);
    if (*r.job.to_us < r.job.from_us) throw UsageError("--to is before --from");
  }
  if (const auto m = a.value("mode")) r.job.mode = *m;
  bool lifetime_view = false;  // the active events drawn (lifetime, compare): what thinning and the colours act on
  for (const render::View& v : parse_flag_with("mode", [&] { return render::parse_view_mode(r.job.mode); }))
    lifetime_view = lifetime_view || v.lifetime;
  if (const auto c = a.value("color"))
    r.job.color = parse_flag_with("color", [&] { return render::parse_color_mode(*c); });
  // Flags that would change nothing (they were accepted and ignored).
  if (!lifetime_view && a.has("no-thinning"))
    throw UsageError("--no-thinning: --mode " + r.job.mode + " draws no lifetime image to thin");
  if (a.has("lifetime-range") && (!lifetime_view || r.job.color != render::ColorMode::lifetime))
    throw UsageError("--lifetime-range sets the lifetime colours: --mode " + r.job.mode + " --color " +
                     std::string(a.value("color").value_or("lifetime")) + " draws none");
  if (const auto s = a.value("scale")) {
    constexpr int kMax = render::FrameStyle::kMaxScale;
    const double v = parse_number<double>("scale", *s, 1, kMax);
    if (v != std::floor(v)) throw UsageError("--scale " + *s + ": a whole number in [1, " + std::to_string(kMax) + "]");
    r.job.scale = static_cast<int>(v);
  }
  r.job.caption = !a.has("no-caption");
  r.job.legend = !a.has("no-legend");
  r.job.thinning = !a.has("no-thinning");
  if (const auto lr = a.value("lifetime-range")) {
    const auto colon = lr->find(':');
    if (colon == std::string::npos) throw UsageError("--lifetime-range " + *lr + ": expected MIN:MAX in ms, e.g. 0.3:30");
    constexpr double kMax = render::FrameStyle::kMaxLifetimeRangeMs;
    r.job.lifetime_min_us = 1000.0 * parse_positive("lifetime-range", lr->substr(0, colon), kMax);
    r.job.lifetime_max_us = 1000.0 * parse_positive("lifetime-range", lr->substr(colon + 1), kMax);
    if (r.job.lifetime_max_us <= r.job.lifetime_min_us) throw UsageError("--lifetime-range: MAX must exceed MIN");
  }
  if (const auto v = a.value("video-fps")) {
    if (!r.job.video) throw UsageError("--video-fps is a video's playback rate; -o " + r.job.output + " is no video");
    r.job.video_fps = parse_number<double>("video-fps", *v, render::kMinVideoFps, render::kMaxVideoFps);
  }

  return r;
}

// Frames per second of recording time -> one progress line now and then.
class FrameProgress {
 public:
  explicit FrameProgress(bool enabled) : enabled_(enabled), tty_(isatty(STDERR_FILENO) == 1) {}
  void update(std::size_t frames, std::size_t total, double t_s) {
    if (!enabled_) return;
    const auto now = std::chrono::steady_clock::now();
    if (now < next_) return;
    next_ = now + (tty_ ? std::chrono::milliseconds(250) : std::chrono::seconds(5));
    char line[160];
    if (total > 0)
      std::snprintf(line, sizeof line, "evlife render: frame %zu/%zu (%.0f %%), t = %.3f s", frames,
                    total, 100.0 * static_cast<double>(frames) / static_cast<double>(total), t_s);
    else
      std::snprintf(line, sizeof line, "evlife render: frame %zu, t = %.3f s", frames, t_s);
    std::fprintf(stderr, tty_ ? "\r\033[K%s" : "%s\n", line);
    std::fflush(stderr);
    drawn_ = true;
  }
  void finish() {
    if (tty_ && drawn_) std::fprintf(stderr, "\r\033[K");
    drawn_ = false;
  }

 private:
  bool enabled_;
  bool tty_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point next_ = std::chrono::steady_clock::now() + std::chrono::milliseconds(500);
};


void print_summary(const RenderArgs& args, const render::AugmentedSource& source,
                   const render::RecordingRenderResult& r, double wall_s) {
  const auto& st = r.stats;
  std::fprintf(stdout, "evlife render: %s -> %s\n", source.description().c_str(), args.job.output.c_str());
  const std::vector<render::View> views = render::parse_view_mode(args.job.mode);
  std::fprintf(stdout, "  frames              %zu (%dx%d px, sensor %dx%d x%d, mode %s, colour %s)\n",
               r.frames, r.frame_size.width, r.frame_size.height, source.sensor().width, source.sensor().height, r.scale,
               args.job.mode.c_str(), std::string(render::to_string(render::color_drawn(args.job.color, views))).c_str());
  if (args.job.video) {
    const render::VideoFrameSize video = render::video_frame_size(r.frame_size.width, r.frame_size.height);
    std::fprintf(stdout, "  video               plays at %g fps%s\n", r.video_fps,
                 args.job.at_us.empty() && r.video_fps < args.job.fps ? " (slow motion: --fps is higher)" : "");
    if (video != render::VideoFrameSize{r.frame_size.width, r.frame_size.height})
      std::fprintf(stdout, "  video size          %dx%d px: frames padded black at the right and bottom (encoders need "
                           "even sides of at least %d px)\n", video.width, video.height, render::kMinVideoSidePx);
  }
  // Noise has no lifetime: the lifetime view never draws it, a fixed window does;
  // thinning removes events from the lifetime view only.
  const auto lifetime_views = std::count_if(views.begin(), views.end(), [](const render::View& v) { return v.lifetime; });
  std::fprintf(stdout, "  events              %llu read, %llu noise (%s), %llu thinned%s\n",
               static_cast<unsigned long long>(st.fed), static_cast<unsigned long long>(st.noise),
               lifetime_views == static_cast<std::ptrdiff_t>(views.size()) ? "never drawn"
               : lifetime_views > 0                                        ? "drawn in the fixed windows only"
                                                                           : "drawn as any event",
               static_cast<unsigned long long>(st.thinned),
               !args.job.thinning    ? " (thinning off)"
               : lifetime_views == 0 ? " (by the estimator; a fixed window draws them)"
                                     : "");
  if (render::ignored_events(st) > 0) std::fprintf(stdout, "  ignored             %s\n", render::ignored_events_text(st).c_str());
  if (const io::EventReader* reader = source.event_reader(); reader && reader->skipped_record_count() > 0)
    std::fprintf(stdout, "  skipped records     %s\n", io::skipped_records_text(*reader).c_str());
  std::fprintf(stdout, "  time range          %s%s\n",
               format_time_range(r.first_t_us, r.last_t_us).c_str(),
               r.exhausted ? "" : " (read so far)");
  if (r.after_end > 0) std::fprintf(stdout, "  note                %zu frame(s) after the last event\n", r.after_end);
  std::fprintf(stdout, "  time                %.2f s wall, %.2f ms per frame drawn\n", wall_s,
               r.frames ? 1e3 * r.draw_s / static_cast<double>(r.frames) : 0.0);
}

int exit_status(const RenderArgs& args, const render::RecordingRenderResult& r) {
  if (r.setup_failed) {  // nothing drawn: the output or the first read failed
    std::fprintf(stderr, "evlife render: %s error: %s\n", r.output_fault ? "output" : "input",
                 (r.output_fault ? *r.output_fault : r.input_fault.value_or("")).c_str());
    return r.output_fault ? kExitOutput : kExitInput;
  }
  if (!args.job.at_us.empty())
    warn_instants_after_end("render", r.after_end, r.first_t_us, r.last_t_us, InstantsOrigin::recording);
  warn_earlier_frames("render", args.job.output, r.earlier_frames);
  // Events the frames left out are named whatever -q says (the summary, -q's to skip, names them too).
  if (args.quiet && render::ignored_events(r.stats) > 0)
    std::fprintf(stderr, "evlife render: warning: not drawn: %s\n", render::ignored_events_text(r.stats).c_str());
  if (r.output_fault) {
    std::fprintf(stderr, "evlife render: output error: %s (%zu frames drawn before it)\n", r.output_fault->c_str(), r.frames);
    return kExitOutput;
  }
  // The output is opened with its first frame: before it, a file of that name is untouched.
  const std::string none_written = "no frame was written (" + args.job.output + " is left as it was)";
  if (r.input_fault) {
    std::fprintf(stderr, "evlife render: input error: %s\nevlife render: %s\n", r.input_fault->c_str(),
                 r.frames == 0 ? none_written.c_str()
                               : fmt::format("the {} frames before the fault were written to {}", r.frames,
                                             args.job.output).c_str());
    return kExitInput;
  }
  if (r.stopped) {
    std::fprintf(stderr, "evlife render: interrupted %s\n",
                 r.frames == 0 ? ("before the first frame: " + none_written).c_str()
                               : fmt::format("after {} frames (kept in {})", r.frames, args.job.output).c_str());
    return kExitInterrupted;
  }
  if (r.frames == 0) {
    std::fprintf(stderr, "evlife render: no frame drawn (--from after the last event?): nothing written to %s\n",
                 args.job.output.c_str());
    return kExitInput;
  }
  return kExitOk;
}

int run_render(int argc, char** argv) {
  const auto wall_start = std::chrono::steady_clock::now();
  RenderArgs args;
  if (const auto done = start_command("render", argc, argv, print_render_help, [&] { args = parse_render_args(argc, argv); })) {
    return *done;
  }
  std::optional<InputSpool> spool;  // INPUT `-` or a pipe: read from a copy
  if (const auto done = spool_stream_input("render", args.input, args.quiet, spool)) return *done;
  if (args.print_config) {
    print_config(args.config, args.sensor);
    return kExitOk;
  }

  const StopRequest stop;  // also over the scan of a file for its sensor size
  std::unique_ptr<render::AugmentedSource> source;
  try {
    source = render::open_augmented_source(args.input, args.config.config.estimator,
                                           user_sensor_size(args.sensor, args.config), args.input_options,
                                           stop.flag());
    if (stop.requested()) {
      std::fprintf(stderr, "evlife render: interrupted while scanning %s for its sensor size: nothing drawn\n",
                   io::name_in_messages(args.input).c_str());
      return kExitInterrupted;
    }
    warn_user_sensor_ignored("render", args.sensor, args.config, args.input, source->sensor());
  } catch (const io::ReadError& e) {
    return open_fault_exit("render", args.input, e);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "evlife render: %s: %s\n", io::name_in_messages(args.input).c_str(), e.what());
    return kExitInput;
  }
  const cv::Size frame = render::frame_size_for(args.job, source->sensor());
  if (const auto refusal = render::frame_memory_refusal(frame)) {
    std::fprintf(stderr, "evlife render: %s (sensor %dx%d at --scale %d): lower --scale\n", refusal->c_str(),
                 source->sensor().width, source->sensor().height, render::frame_style(args.job, source->sensor()).scale);
    return kExitUsage;
  }
  FrameProgress progress(!args.quiet);
  const render::RecordingRenderResult result = [&] {
    return render::render_recording(
        *source, args.job,
        [&](std::size_t frames, std::size_t total, double t_s) { progress.update(frames, total, t_s); },
        stop.flag(), [&](const render::EventGap& gap) {
          progress.finish();  // a terminal's progress line cleared first, not run on into
          std::fprintf(stderr,
                       "evlife render: warning: %s --to T stops before it (Ctrl-C stops here, keeping the "
                       "frames drawn)\n",
                       gap.text(args.job.fps).c_str());
        });
  }();
  progress.finish();
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  if (result.no_events) {
    std::fprintf(stderr, "evlife render: %s: nothing to draw\n",
                 args.input_options.filters() ? no_event_text(args.input, args.input_options).c_str()
                                              : (io::name_in_messages(args.input) + " holds no event").c_str());
    return kExitInput;
  }
  if (!args.quiet && !result.setup_failed) print_summary(args, *source, result, wall_s);
  return exit_status(args, result);
}

}  // namespace

EVLIFE_REGISTER_COMMAND("render", "draw active events at any instant: PNG frames or a video", run_render);

}  // namespace evlife::cli::render_command
