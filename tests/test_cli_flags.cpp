// The command line's shared conventions, run as a user would (the built
// binary): the same flag for the same thing in every command (old spellings
// kept as aliases), -i/--input, --version, "did you mean", --print-config on
// every command that reads the configuration, times with units everywhere,
// one range per option (the engine's table) and the recording's time range
// in the summaries.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "cli_runner.h"
#include "scratch_dir.h"

namespace {

namespace fs = std::filesystem;
const std::string kCli = EVLIFE_CLI_PATH;
using RunResult = evlife::test::CliRun;

class CliFlags : public testing::Test {
 protected:
  RunResult run(const std::string& args) const {
    return evlife::test::run_cli(kCli, args, dir_.path() / "cli.log");
  }
  std::string path(const std::string& name) const { return dir_.file(name); }
  // A 0.3 s synthetic recording (the synth command itself is tested elsewhere).
  std::string sample() const {
    const std::string p = path("s.txt");
    if (!fs::exists(p)) {
      EXPECT_EQ(run("synth -q --scene edges -o " + p + " --duration 300ms").exit_code, 0);
    }
    return p;
  }
  // Two events, a user's smallest text file (read with --sensor 8x8).
  std::string two_events() const {
    const std::string p = path("two.txt");
    if (!fs::exists(p)) std::ofstream(p) << "0.000001 1 1 1\n0.000002 2 2 0\n";
    return p;
  }
  const evlife::test::ScratchDir dir_{"test_cli_flags"};
};

bool has(const RunResult& r, const std::string& text) { return r.output.find(text) != std::string::npos; }

TEST_F(CliFlags, VersionEverywhere) {
  const RunResult top = run("--version");
  EXPECT_EQ(top.exit_code, 0);
  EXPECT_TRUE(has(top, "evlife 0.")) << top.output;
  for (const std::string command : {"process", "render", "eval", "run", "convert", "synth", "info", "devices"}) {
    const RunResult cmd = run(command + " --version");
    EXPECT_EQ(cmd.exit_code, 0) << command;
    EXPECT_EQ(cmd.output, top.output) << command;
  }
  const RunResult help = run("help process");  // `evlife help CMD` = `evlife CMD --help`
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_EQ(help.output, run("process --help").output);
}

TEST_F(CliFlags, AnOutputOfTheWrongKindIsAUsageError) {
  EXPECT_EQ(run("synth -q --duration 10ms -o " + path("s.csv")).exit_code, 2);
  EXPECT_EQ(run("convert " + sample() + " " + path("x.dat")).exit_code, 2);
  EXPECT_EQ(run("process " + sample() + " -o " + path("x.xyz")).exit_code, 2);
  EXPECT_EQ(run("render " + sample() + " -o " + path("x.mp4") + " --fps 10 --video-fps 100").exit_code, 2);
}

TEST_F(CliFlags, AStrayEventThatSetsAHugeSensorIsPointedOut) {
  std::ofstream(path("stray.txt")) << "0.000001 1 1 1\n0.000002 2 2 0\n0.000003 3000 2 1\n";
  const RunResult r = run("process " + path("stray.txt") + " -o " + path("stray.bin"));
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_TRUE(has(r, "span 3001x3 pixels; if the sensor is smaller, pass --sensor")) << r.output;
  EXPECT_FALSE(has(run("process " + sample() + " -o " + path("ok.bin")), "span")) << "a normal scene";
}

TEST_F(CliFlags, AFileWithNoEventIsAnInputErrorNotAOneByOneSensor) {
  std::ofstream(path("empty.txt")).flush();
  const RunResult r = run("process " + path("empty.txt") + " -o " + path("e.csv"));
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_TRUE(has(r, "no events")) << r.output;
}

TEST_F(CliFlags, DidYouMeanForCommandsAndFlags) {
  const RunResult c = run("proces x");
  EXPECT_EQ(c.exit_code, 2);
  EXPECT_TRUE(has(c, "did you mean 'process'")) << c.output;
  const RunResult f = run("run --source synth:edges --duraton 1");
  EXPECT_EQ(f.exit_code, 2);
  EXPECT_TRUE(has(f, "did you mean '--duration'")) << f.output;
  const RunResult far = run("process --zzzzzzzz");
  EXPECT_EQ(far.exit_code, 2);
  EXPECT_FALSE(has(far, "did you mean")) << far.output;
}

// `info` has no -q (its help lists none: its output is the description): it
// is refused, without the guess "did you mean '--to'?" that any one-letter
// option got.
TEST_F(CliFlags, AnUnknownOneLetterOptionGetsNoGuess) {
  const RunResult help = run("info --help");
  EXPECT_FALSE(has(help, "-q")) << help.output;
  const RunResult q = run("info -q " + sample());
  EXPECT_EQ(q.exit_code, 2);
  EXPECT_TRUE(has(q, "unknown option '-q'")) << q.output;
  EXPECT_FALSE(has(q, "did you mean")) << q.output;
  EXPECT_FALSE(has(run("process -x " + sample()), "did you mean"));
}

// -j2 and -oFILE as getopt takes them (help names -j and -o; they were
// refused as "unknown option '-j2' (did you mean '--to'?)").
TEST_F(CliFlags, ShortOptionsTakeAnAttachedValue) {
  const std::string in = sample();
  const RunResult attached = run("run " + in + " -j2 -o" + path("attached.bin") + " -q");
  EXPECT_EQ(attached.exit_code, 0) << attached.output;
  EXPECT_EQ(run("run " + in + " -j 2 -o " + path("apart.bin") + " -q").exit_code, 0);
  std::ifstream a(path("attached.bin"), std::ios::binary), b(path("apart.bin"), std::ios::binary);
  const std::string bytes_a((std::istreambuf_iterator<char>(a)), {}), bytes_b((std::istreambuf_iterator<char>(b)), {});
  EXPECT_FALSE(bytes_a.empty());
  EXPECT_EQ(bytes_a, bytes_b);
  const RunResult flag = run("process " + in + " -qx -o " + path("q.bin"));  // -q takes no value
  EXPECT_EQ(flag.exit_code, 2);
  EXPECT_TRUE(has(flag, "unknown option '-qx'")) << flag.output;
  const RunResult twice = run("run " + in + " -j2 --workers 1 -q");
  EXPECT_EQ(twice.exit_code, 2);
  EXPECT_TRUE(has(twice, "'-j' and '--workers' are the same option")) << twice.output;
}

TEST_F(CliFlags, PrintConfigOnEveryCommandThatReadsIt) {
  for (const char* cmd : {"process", "render", "eval", "run"}) {
    const RunResult r = run(std::string(cmd) + " --print-config --set estimator.window_size=9");
    EXPECT_EQ(r.exit_code, 0) << cmd << ": " << r.output;
    EXPECT_TRUE(has(r, "window_size: 9")) << cmd << ": " << r.output;
    EXPECT_TRUE(has(r, "batches_per_worker: 64")) << cmd << ": " << r.output;
  }
}

TEST_F(CliFlags, OneRangePerEngineOption) {
  // The range of the table next to EngineOptions, for the flag and the key.
  const std::string src = "run --source synth:edges --sensor 64x64 --duration 10ms -q ";
  const RunResult flag = run(src + "--queue-batches 1025");
  EXPECT_EQ(flag.exit_code, 2);
  EXPECT_TRUE(has(flag, "[2, 1024]")) << flag.output;
  const RunResult key = run(src + "--set engine.batches_per_worker=1025");
  EXPECT_EQ(key.exit_code, 2);
  EXPECT_TRUE(has(key, "[2, 1024]")) << key.output;
  EXPECT_EQ(run(src + "--queue-batches 1024").exit_code, 0);
  const RunResult help = run("run --help");
  EXPECT_TRUE(has(help, "--queue-batches N")) << help.output;
}

TEST_F(CliFlags, TimesWithUnitsEverywhere) {
  const std::string in = sample();
  const RunResult scene = run("run --source synth:edges --sensor 64x64 --duration 50ms --stats-period 500ms");
  EXPECT_EQ(scene.exit_code, 0) << scene.output;
  // The scene is named as given, with its size and length (before: "file:<synthetic>").
  EXPECT_TRUE(has(scene, "synth:edges (a generated scene, 64x64, 0.05 s) ->")) << scene.output;
  EXPECT_EQ(run("render " + in + " -o " + path("a.png") + " --at 150ms -q").exit_code, 0);
  EXPECT_TRUE(fs::exists(path("a.png")));
  const RunResult bad = run("synth -o " + path("x.txt") + " --duration 5parsecs");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_TRUE(has(bad, "--duration 5parsecs")) << bad.output;
  // Every refused length is told synth's one range (-1 was told "0 or at least 1us", then 0 was refused).
  for (const char* d : {"-1", "0", "1us", "5parsecs", "3601s"}) {
    const RunResult refused = run("synth -o " + path("x.txt") + " --duration " + std::string(d));
    EXPECT_EQ(refused.exit_code, 2) << d;
    EXPECT_TRUE(has(refused, "--duration " + std::string(d) + ": expected 1ms..3600s")) << refused.output;
  }
}

TEST_F(CliFlags, InputAndOutputSpellings) {
  const std::string in = sample();
  // -i for the input; convert takes -o as well as a second name.
  EXPECT_EQ(run("process -i " + in + " -o " + path("a.bin") + " -q").exit_code, 0);
  EXPECT_EQ(run("convert -i " + in + " -o " + path("b.h5") + " -q").exit_code, 0);
  EXPECT_TRUE(fs::exists(path("b.h5")));
  EXPECT_EQ(run("info -i " + in).exit_code, 0);
  // run FILE = run --source FILE: the same output bytes.
  EXPECT_EQ(run("run " + in + " -q -o " + path("r1.bin")).exit_code, 0);
  EXPECT_EQ(run("run --source " + in + " -q -o " + path("r2.bin")).exit_code, 0);
  EXPECT_EQ(evlife::test::read_text_file(path("r1.bin")), evlife::test::read_text_file(path("r2.bin")));
  EXPECT_EQ(run("run " + in + " --source " + in).exit_code, 2);
}

TEST_F(CliFlags, RenderAndRunShareTheirFrameFlags) {
  const std::string in = sample();
  // render: --frames DIR (run's spelling) = -o DIR; --render-mode/--render-fps accepted.
  ASSERT_EQ(run("render " + in + " --frames " + path("f") + " --render-mode compare --at 0.1 -q").exit_code, 0);
  ASSERT_EQ(run("render " + in + " -o " + path("g") + " --mode compare --at 0.1 -q").exit_code, 0);
  EXPECT_EQ(evlife::test::read_text_file(path("f") + "/frame_000000_t0.100000s.png"),
            evlife::test::read_text_file(path("g") + "/frame_000000_t0.100000s.png"));
  // run: --mode/--fps (render's spelling) and the old --render-* ones.
  EXPECT_EQ(run("run " + in + " -q --fps 0 --at 0.1 --mode compare --frames " + path("h")).exit_code, 0);
  EXPECT_EQ(run("run " + in + " -q --render-fps 0 --at 0.1 --render-mode compare --frames " + path("k")).exit_code, 0);
  EXPECT_EQ(std::distance(fs::directory_iterator(path("h")), fs::directory_iterator{}), 1);
  EXPECT_EQ(std::distance(fs::directory_iterator(path("k")), fs::directory_iterator{}), 1);
}

// A frame rate so slow that one interval overflowed the µs clock: render
// looped forever (100 % CPU, deaf to SIGTERM, no frame); a video rate the
// encoders refuse was reported as a video that cannot be opened (exit 4).
TEST_F(CliFlags, FrameRatesTheClockOrTheEncodersCannotTakeAreRefused) {
  const std::string in = sample();
  for (const std::string fps : {"1e-13", "1e-300"}) {
    const RunResult r = run("render " + in + " -o " + path("slow") + " --fps " + fps + " --to 0.2 -q");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_TRUE(has(r, "--fps " + fps + ": expected a number in [1e-06, 1e+06]")) << r.output;
  }
  const RunResult run_slow = run("run " + in + " -q --fps 1e-9 --frames " + path("h"));
  EXPECT_EQ(run_slow.exit_code, 2) << run_slow.output;
  EXPECT_TRUE(has(run_slow, "expected 0 (the --at instants only) or a number in [1e-06, 100000]")) << run_slow.output;
  EXPECT_EQ(run("render " + in + " -o " + path("day") + " --fps 1e-6 -q").exit_code, 0);  // the slowest: one frame
  EXPECT_EQ(std::distance(fs::directory_iterator(path("day")), fs::directory_iterator{}), 1);
  const RunResult video = run("render " + in + " -o " + path("v.avi") + " --fps 10 --video-fps 0.001 -q");
  EXPECT_EQ(video.exit_code, 2) << video.output;
  EXPECT_TRUE(has(video, "--video-fps 0.001: expected a number in [0.01, 60]")) << video.output;
  const RunResult run_video = run("run " + in + " -q --fps 0.001 --video " + path("r.avi"));
  EXPECT_EQ(run_video.exit_code, 2) << run_video.output;
  EXPECT_TRUE(has(run_video, "--video plays at --fps: at least 0.01")) << run_video.output;
  // render's video plays at --fps by default: within the encoders' range.
  const RunResult slow_video = run("render " + in + " -o " + path("s.avi") + " --fps 0.001 -q");
  EXPECT_EQ(slow_video.exit_code, 0) << slow_video.output;
  EXPECT_GT(fs::file_size(path("s.avi")), 0u);
}

TEST_F(CliFlags, TimeRangeInSummariesAndAWarningPastTheEnd) {
  const std::string in = sample();
  const RunResult p = run("process " + in + " -o " + path("a.bin"));
  EXPECT_EQ(p.exit_code, 0);
  EXPECT_TRUE(has(p, "time range")) << p.output;
  // 300000 (meant as microseconds) is 300000 s: after the end; the user is told.
  const RunResult r = run("render " + path("a.bin") + " -o " + path("late.png") + " --at 300000");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_TRUE(has(r, "warning: 1 of the --at instants lie after the last event")) << r.output;
  EXPECT_TRUE(has(r, "time range")) << r.output;
  const RunResult ok = run("render " + path("a.bin") + " -o " + path("in.png") + " --at 0.2");
  EXPECT_FALSE(has(ok, "warning")) << ok.output;
  // run --at says it too (it drew the frame in silence).
  const RunResult run_late = run("run " + in + " --frames " + path("run_late") + " --fps 0 --at 0.2,300000,5 -q");
  EXPECT_EQ(run_late.exit_code, 0) << run_late.output;
  EXPECT_TRUE(has(run_late, "evlife run: warning: 2 of the --at instants lie after the last event (the events read "
                            "span 0.29")) << run_late.output;
  // With --from, the instants count from the first event read: the span said is the crop's.
  const RunResult run_crop = run("run " + in + " --from 0.2 --frames " + path("run_crop") + " --fps 0 --at 0.05,0.2 -q");
  EXPECT_TRUE(has(run_crop, "warning: 1 of the --at instants lie after the last event (the events read span 0.09"))
      << run_crop.output;
  const RunResult run_ok = run("run " + in + " --frames " + path("run_ok") + " --fps 0 --at 0.2 -q");
  EXPECT_FALSE(has(run_ok, "warning")) << run_ok.output;
  const RunResult none = run("process " + in + " -o " + path("none.bin") + " --from 300000");
  EXPECT_EQ(none.exit_code, 0);
  EXPECT_TRUE(has(none, "warning: no event of")) << none.output;
  const RunResult none_run = run("run " + in + " -o " + path("none_run.bin") + " --from 300000");
  EXPECT_EQ(none_run.exit_code, 0);
  EXPECT_TRUE(has(none_run, "warning: no event of " + in + " within --from/--to")) << none_run.output;
  const RunResult e = run("eval " + path("a.bin") + " -o " + path("ev") + " --at 2s");
  EXPECT_EQ(e.exit_code, 0) << e.output;
  EXPECT_TRUE(has(e, "time range")) << e.output;
  EXPECT_TRUE(has(e, "warning: --frame-at 2.000000 s lies after the last event")) << e.output;
  // Not for the default instant (0.5 s) on a recording shorter than it: no flag of the user's was wrong.
  const RunResult d = run("eval " + path("a.bin") + " -o " + path("ev_default"));  // 300 ms long
  EXPECT_EQ(d.exit_code, 0) << d.output;
  EXPECT_FALSE(has(d, "--frame-at")) << d.output;
  // eval of a crop that holds nothing says so, as process does (its report of NaN was unexplained).
  const RunResult empty = run("eval " + in + " -o " + path("ev0") + " --from 300000");
  EXPECT_EQ(empty.exit_code, 0) << empty.output;
  EXPECT_TRUE(has(empty, "warning: no event of " + in + " within --from/--to")) << empty.output;
  EXPECT_FALSE(has(empty, "drawn at the last event")) << empty.output;
}

}  // namespace

namespace {

// What a command prints must reach its reader: stdout on a full disk is an
// output error (exit 4, named), not exit 0 with the text lost.
TEST_F(CliFlags, AFullStandardOutputIsAnOutputError) {
  for (const std::string& command : {"info " + sample(), std::string("process --print-config"), std::string("--help")}) {
    const RunResult r = evlife::test::run_cli("/bin/sh", "-c \"'" + kCli + "' " + command + " >/dev/full\"",
                                              dir_.path() / "sh.log");
    EXPECT_EQ(r.exit_code, 4) << command << ": " << r.output;
    EXPECT_TRUE(has(r, "cannot write the standard output: No space left on device")) << command << ": " << r.output;
  }
}

// --print-config given back with --config configures the same run: the
// sensor, which the input decides unless the user sets it, stays a comment
// (before, it bound every input to 128 x 128: a 346 x 260 scene was refused).
TEST_F(CliFlags, PrintedConfigurationGivenBackConfiguresTheSameRun) {
  const std::string scene = path("wide.txt");
  ASSERT_EQ(run("synth -q --scene edges --sensor 346x260 --duration 20ms -o " + scene).exit_code, 0);
  const RunResult printed = run("process --print-config --set estimator.window_size=7");
  ASSERT_EQ(printed.exit_code, 0) << printed.output;
  EXPECT_TRUE(has(printed, "    # width: 128\n    # height: 128\n")) << printed.output;
  std::ofstream(path("printed.yaml")) << printed.output;
  ASSERT_EQ(run("process -q " + scene + " -o " + path("a.bin") + " --set estimator.window_size=7").exit_code, 0);
  const RunResult again = run("process -q " + scene + " -o " + path("b.bin") + " --config " + path("printed.yaml"));
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_EQ(evlife::test::read_text_file(path("a.bin")), evlife::test::read_text_file(path("b.bin")));
  // Set by the user, the size is printed as values (both keys: one alone is refused).
  const RunResult set = run("process --print-config --set estimator.sensor.width=300 --set estimator.sensor.height=200");
  EXPECT_TRUE(has(set, "    width: 300\n    height: 200\n")) << set.output;
  // --sensor too, the size of the run it prints (it stayed a comment: the file given back ran at another size).
  const RunResult flag = run("process --print-config --sensor 400x300");
  EXPECT_TRUE(has(flag, "    width: 400\n    height: 300\n")) << flag.output;
  std::ofstream(path("sized.yaml")) << flag.output;
  ASSERT_EQ(run("process -q " + scene + " --sensor 400x300 -o " + path("c.bin")).exit_code, 0);
  ASSERT_EQ(run("process -q " + scene + " --config " + path("sized.yaml") + " -o " + path("d.bin")).exit_code, 0);
  EXPECT_EQ(evlife::test::read_text_file(path("c.bin")), evlife::test::read_text_file(path("d.bin")));
  // A newline in a --set (its key is trimmed) stays inside the header's comment: the file loads back.
  const RunResult newline = run("process --print-config --set '\nestimator.window_size=7'");
  ASSERT_EQ(newline.exit_code, 0) << newline.output;
  std::ofstream(path("newline.yaml")) << newline.output;
  EXPECT_EQ(run("process --print-config --config " + path("newline.yaml")).exit_code, 0);
  // `run` prints the engine's flags as the configuration they make, and checks them.
  const RunResult engine = run("run --print-config --workers 3 --tiles 2x2");
  EXPECT_TRUE(has(engine, "workers: 3\n")) << engine.output;
  EXPECT_TRUE(has(engine, "tiles_x: 2\n")) << engine.output;
  EXPECT_EQ(run("run --print-config --workers 99").exit_code, 2);
}

// A configuration file that is no file, one that says a key twice, holds two
// documents or gives a section a value: usage errors naming the place (a
// directory was an "unexpected error", the rest passed silently).
TEST_F(CliFlags, ConfigurationFilesThatSayTooMuchOrNothingAreNamed) {
  const auto config_error = [&](const std::string& yaml, const std::string& says) {
    std::ofstream(path("c.yaml")) << yaml;
    const RunResult r = run("process --print-config --config " + path("c.yaml"));
    EXPECT_EQ(r.exit_code, 2) << yaml << r.output;
    EXPECT_TRUE(has(r, says)) << yaml << r.output;
  };
  config_error("estimator:\n  window_size: 7\n  window_size: 9\n", "c.yaml:3: estimator.window_size is already given at line 2");
  config_error("estimator:\n  window_size: 7\nestimator:\n  seed: 3\n", "c.yaml:3: estimator is already given at line 1");
  config_error("estimator:\n  window_size: 7\n---\nestimator:\n  window_size: 9\n", "c.yaml:3: a second YAML document");
  // yaml-cpp 0.7's LoadAll looped for ever, allocating, on a stray ',' (a hang that filled memory).
  config_error("# a comment\n  ,\n", "c.yaml:2: YAML syntax error: the file cannot be read past this point");
  config_error("estimator:\n  window_size: {a: 1}\n", "estimator.window_size must be a single value");
  config_error("estimator: 5\n", "estimator is a section");
  // An INI file: its "[estimator]" is a YAML list, what follows it a second document.
  config_error("[estimator]\nwindow_size = 7\n", "c.yaml:1: expected a map of sections at top level (an INI-style [section]");
  config_error(std::string("\x89PNG\r\n\x1a\n\0\0\0\rIHDR", 16), "c.yaml: not a YAML text file (a NUL byte at offset 8)");
  // Half a sensor size would pair with the other key's default (128), not with the input's size.
  config_error("estimator:\n  sensor:\n    width: 300\n",
               "estimator.sensor.width is set at " + path("c.yaml") + ":3, estimator.sensor.height is not: set both");
  const RunResult dir = run("process --print-config --config " + dir_.path().string());
  EXPECT_EQ(dir.exit_code, 2) << dir.output;
  EXPECT_TRUE(has(dir, "is a directory, not a configuration file")) << dir.output;
  // A path the system cannot even look at (a symlink loop) is the file's fault, exit 2 (it was
  // exit 1, "unexpected error: filesystem error: status: Too many levels of symbolic links").
  std::filesystem::create_symlink(path("loop2.yaml"), path("loop1.yaml"));
  std::filesystem::create_symlink(path("loop1.yaml"), path("loop2.yaml"));
  const RunResult loop = run("process --print-config --config " + path("loop1.yaml"));
  EXPECT_EQ(loop.exit_code, 2) << loop.output;
  EXPECT_TRUE(has(loop, "loop1.yaml: cannot read the configuration file: Too many levels of symbolic links"))
      << loop.output;
  EXPECT_EQ(run("process --print-config --config ''").exit_code, 2);
  // A section whose keys are all commented out sets nothing.
  std::ofstream(path("c.yaml")) << "estimator:\n  sensor:\n    # width: 300\n";
  EXPECT_EQ(run("process --print-config --config " + path("c.yaml")).exit_code, 0);
}

// The help names the configuration read without --config: the compiled-in
// file, not a path relative to the working directory (which is not read);
// and -i where the commands take it (synth and devices do not).
TEST_F(CliFlags, HelpNamesTheConfigurationReadAndWhoTakesInput) {
  const std::string shipped = std::string(EVLIFE_SOURCE_DIR) + "/config/evlife.yaml";
  for (const std::string command : {"process", "render", "eval", "run"}) {
    const RunResult help = run(command + " --help");
    EXPECT_TRUE(has(help, shipped)) << command << help.output;
    EXPECT_FALSE(has(help, "default: config/evlife.yaml")) << command << help.output;
  }
  EXPECT_TRUE(has(run("--help"), "without --config: " + shipped)) << run("--help").output;
  for (const std::string command : {"process", "render", "eval", "run", "info", "convert"}) {
    const RunResult r = run(command + " -i " + path("missing.txt") + " -o " + path("x.bin"));
    EXPECT_FALSE(has(r, "unknown option '-i'")) << command << r.output;
  }
  EXPECT_TRUE(has(run("--help"), "all but synth and devices take\n-i/--input FILE")) << run("--help").output;
  EXPECT_TRUE(has(run("synth -i x"), "unknown option '-i'"));
}

// Every flag a command accepts is named in its --help (README: "every command
// has a --help that explains its flags with an example"), read from the option
// table of its engine/cli/cmd_<name>.cpp, aliases and other spellings included
// (--help itself is said once, by `evlife --help`). process, info and convert
// took -i/--input without naming it, info had no example.
TEST_F(CliFlags, EveryHelpNamesEveryFlagTheCommandTakesAndGivesAnExample) {
  const std::vector<std::pair<std::string, std::string>> shared = {
      {"kInputOptionSpec", "input"}, {"kConfigOptionSpec", "config"}, {"kSetOptionSpec", "set"},
      {"kPrintConfigOptionSpec", "print-config"}, {"kTopicOptionSpec", "topic"},
      {"kTimeUnitOptionSpec", "time-unit"}, {"kPolarityOptionSpec", "polarity"},
      {"kFromOptionSpec", "from"}, {"kToOptionSpec", "to"}};
  // {"name", 'a' or 0, ..., "also,names"} in the command's OptionSpec table.
  const std::regex entry(R"re(\{"([a-z0-9-]+)",\s*(?:'(.)'|0)\s*,\s*(?:true|false)\s*,\s*(?:true|false)\s*(?:,\s*"([a-z0-9,-]*)")?\s*\})re");
  for (const std::string command : {"convert", "eval", "info", "process", "render", "run", "synth"}) {
    std::ifstream in(std::string(EVLIFE_SOURCE_DIR) + "/engine/cli/cmd_" + command + ".cpp");
    ASSERT_TRUE(in) << command;
    const std::string source((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::size_t begin = source.find("OptionSpec k");
    ASSERT_NE(begin, std::string::npos) << command;
    const std::string table = source.substr(begin, source.find("};", begin) - begin);
    std::set<std::string> flags;
    for (std::sregex_iterator m(table.begin(), table.end(), entry), end; m != end; ++m) {
      flags.insert("--" + (*m)[1].str());
      if ((*m)[2].matched) flags.insert("-" + (*m)[2].str());
      std::stringstream also((*m)[3].str());
      for (std::string name; std::getline(also, name, ',');) {
        if (!name.empty()) flags.insert("--" + name);
      }
    }
    for (const auto& [constant, name] : shared) {
      if (table.find(constant) != std::string::npos) flags.insert("--" + name);
    }
    if (table.find("kInputOptionSpec") != std::string::npos) flags.insert("-i");
    flags.erase("--help");
    flags.erase("-h");
    ASSERT_GE(flags.size(), 3u) << command << ": the option table was not found in its source";
    const RunResult help = run(command + " --help");
    ASSERT_EQ(help.exit_code, 0) << command;
    for (const std::string& flag : flags) {
      // The flag as a word: not "--topic" inside "--topics", nor "-i" in "--input".
      const std::regex named("(^|[^A-Za-z0-9-])" + flag + "([^A-Za-z0-9-]|$)");
      EXPECT_TRUE(std::regex_search(help.output, named)) << command << " --help does not name " << flag;
    }
    EXPECT_TRUE(has(help, "Example")) << command << " --help has no example";
  }
  EXPECT_TRUE(has(run("devices --help"), "Example")) << "devices --help has no example";
}

// A lifetime range's MIN has one range, whether zero or negative.
TEST_F(CliFlags, LifetimeRangeNamesOneRangeForEveryValueOutsideIt) {
  for (const std::string range : {"-1:5", "0:30", "x:30"}) {
    const RunResult r = run("render " + sample() + " -o " + path("l.png") + " --at 0.1 --lifetime-range " + range);
    EXPECT_EQ(r.exit_code, 2) << range << r.output;
    EXPECT_TRUE(has(r, ": expected a number in (0, 1000000000]")) << range << r.output;
  }
}

// A whole-number flag given a fraction names its own range, not int64's;
// given no count at all ("nan", hex, past a double, 2.0) too, not the parser's
// placeholder ("expected a number in [-1e+300, 1e+300]" before).
TEST_F(CliFlags, AWholeNumberFlagNamesItsRange) {
  const RunResult r = run("run " + sample() + " --workers 2.5");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(has(r, "--workers 2.5: expected a whole number in [1, 32]")) << r.output;
  for (const auto& [flag, said] : std::vector<std::pair<std::string, std::string>>{
           {"--workers nan", "--workers nan: expected a whole number in [1, 32]"},
           {"--batch-events 0x10", "--batch-events 0x10: expected a whole number in [16, 65536]"},
           {"--margin 1e400", "--margin 1e400: expected a whole number in -1 (auto) or [0, 1024]"},
           // A count in decimal digits, as its key (--set engine.workers=2.0 is refused too).
           {"--workers 2.0", "--workers 2.0: expected a whole number in [1, 32]"},
           {"--batch-events 1e3", "--batch-events 1e3: expected a whole number in [16, 65536]"},
           {"--tiles 2.0x2", "--tiles 2.0: expected a whole number in [1, 256]"}}) {
    const RunResult bad = run("run " + sample() + " -q " + flag);
    EXPECT_EQ(bad.exit_code, 2) << flag;
    EXPECT_TRUE(has(bad, said)) << bad.output;
    EXPECT_FALSE(has(bad, "1e+300")) << bad.output;
  }
}

// More tiles than the sensor has pixels across, by the flag or the key:
// the refusal names the flag, its value and the sensor (before: exit 2
// "tiles_x: must be 1..min(sensor width, 4096)", the layout's field name).
TEST_F(CliFlags, TilesBeyondTheSensorNameTheFlagAndTheSensor) {
  const std::string src = "run --source synth:edges --sensor 32x24 --duration 10ms -q ";
  const RunResult flag = run(src + "--tiles 40x2");
  EXPECT_EQ(flag.exit_code, 2) << flag.output;
  EXPECT_TRUE(has(flag, "--tiles 40x2: more tiles than pixels across the 32x24 sensor")) << flag.output;
  EXPECT_TRUE(has(flag, "at most --tiles 32x2")) << flag.output;
  const RunResult key = run(src + "--set engine.tiles_y=30");
  EXPECT_EQ(key.exit_code, 2) << key.output;
  EXPECT_TRUE(has(key, "--tiles 1x30: more tiles than pixels across the 32x24 sensor")) << key.output;
  EXPECT_FALSE(has(key, "tiles_y: must be")) << key.output;
}

// Frames of a sensor of a few pixels: the default upscaling stays within
// its limit (it asked for 42 at 12 x 12: "unexpected error").
TEST_F(CliFlags, ATinySensorRendersAndEvaluates) {
  const std::string tiny = path("tiny.txt");
  ASSERT_EQ(run("synth -q --sensor 12x12 --duration 300ms -o " + tiny).exit_code, 0);
  const RunResult frame = run("render " + tiny + " -q -o " + path("tiny.png") + " --at 0.2");
  EXPECT_EQ(frame.exit_code, 0) << frame.output;
  EXPECT_TRUE(fs::file_size(path("tiny.png")) > 0);
  const RunResult report = run("eval " + tiny + " -q -o " + path("tiny_eval"));
  EXPECT_EQ(report.exit_code, 0) << report.output;
}

}  // namespace

namespace {

// Flags that would select nothing are refused, not ignored: the input
// selection on evlife's own output (read whole), --from/--to/--polarity on a
// synthetic source, --duration on a file, --topic / --time-unit on a format
// that has no topics / states its times.
TEST_F(CliFlags, AFlagWithNothingToActOnIsRefused) {
  const std::string out = path("p.bin");
  ASSERT_EQ(run("process -q " + sample() + " -o " + out).exit_code, 0);
  for (const std::string& command : {"info " + out + " --from 0.1", "info " + out + " --polarity on",
                                     "convert " + out + " " + path("c.csv") + " --to 0.2",
                                     "render " + out + " -o " + path("f.png") + " --at 0.1 --polarity off",
                                     "eval " + out + " -o " + path("ev") + " --polarity on"}) {
    const RunResult r = run(command);
    EXPECT_EQ(r.exit_code, 2) << command << ": " << r.output;
    EXPECT_TRUE(has(r, "nothing to select in " + out + ", evlife's output")) << command << ": " << r.output;
  }
  EXPECT_EQ(run("info " + out + " --polarity both").exit_code, 0);  // selects nothing: allowed
  const RunResult synth = run("run synth:mixed --duration 100ms --from 0.05 -q");
  EXPECT_EQ(synth.exit_code, 2) << synth.output;
  EXPECT_TRUE(has(synth, "--from/--to select the events of a file; the source synth:mixed is none")) << synth.output;
  const RunResult duration = run("run " + sample() + " --duration 100ms -q");
  EXPECT_EQ(duration.exit_code, 2) << duration.output;
  EXPECT_EQ(run("run file: -q").exit_code, 2);
  EXPECT_EQ(run("synth -q --pixel dvs --jitter-us 500 --duration 10ms -o " + path("j.txt")).exit_code, 2);
  EXPECT_EQ(run("render " + sample() + " -q -o " + path("pngs") + " --fps 10 --video-fps 5").exit_code, 2);
  // A format with one stream and its own time unit: a usage error of every
  // command (it was exit 3, an input error, though the file was sound).
  for (const std::string& command :
       {"info " + sample(), "process -q " + sample() + " -o " + path("t.bin"),
        "run -q " + sample() + " -o " + path("t.bin"), "convert " + sample() + " " + path("t.csv"),
        "render -q " + sample() + " -o " + path("t.png") + " --at 0.1", "eval -q " + sample() + " -o " + path("tev")}) {
    const RunResult topic = run(command + " --topic /dvs/events");
    EXPECT_EQ(topic.exit_code, 2) << command << ": " << topic.output;
    EXPECT_TRUE(has(topic, "--topic chooses a stream of a ROS bag, MCAP or HDF5 file or an array of an .npz; "
                           "this rpg-text file"))
        << command << ": " << topic.output;
    const RunResult unit = run(command + " --time-unit ns");
    EXPECT_EQ(unit.exit_code, 2) << command << ": " << unit.output;
    EXPECT_TRUE(has(unit, "--time-unit gives the time column's unit of CSV/text, NumPy and HDF5 files")) << unit.output;
    EXPECT_TRUE(has(unit, "(see evlife " + command.substr(0, command.find(' ')) + " --help)")) << unit.output;
  }
  // A replay's pacing and sensor on the camera (refused before it is opened: no camera needed here).
  for (const char* given : {"--realtime=0.5", "--packet-us 500", "--sensor 64x64"}) {
    const std::string flag = given;
    const RunResult camera = run("run --source dvs128 -q " + flag);
    EXPECT_EQ(camera.exit_code, 2) << flag << "\n" << camera.output;
    EXPECT_TRUE(has(camera, flag.substr(0, flag.find_first_of(" =")) + " sets a replay or a synth: scene; the camera dvs128"))
        << camera.output;
  }
  // A replay's packets without its pacing (the replay ran unpaced, the flag unread).
  const RunResult packets = run("run " + sample() + " --packet-us 10 -q");
  EXPECT_EQ(packets.exit_code, 2) << packets.output;
  EXPECT_TRUE(has(packets, "--packet-us sets the packets of a paced replay: add --realtime")) << packets.output;
  EXPECT_EQ(run("run " + sample() + " --packet-us 10 --realtime=100 -q").exit_code, 0);
  // A positive time under the clock's microsecond (as 0, "no progress lines").
  const RunResult period = run("run " + sample() + " --stats-period 1e-9 -q");
  EXPECT_EQ(period.exit_code, 2) << period.output;
  EXPECT_TRUE(has(period, "--stats-period 1e-9: expected a time such as")) << period.output;
  EXPECT_TRUE(has(period, "0 or at least 1us (to the nearest us), at most 1e9s")) << period.output;
  // The upper bound is said (a time past it was told the form, which it had).
  const RunResult far = run("render " + sample() + " --at 1000000001 --frames " + path("far"));
  EXPECT_EQ(far.exit_code, 2) << far.output;
  EXPECT_TRUE(has(far, "at most 1e9s")) << far.output;
  EXPECT_EQ(run("run " + sample() + " --stats-period 0.6us -q").exit_code, 0);
  // The same rule for its key (it read 1e-9 s as a period of 1 ns: a progress line every few ms),
  // as a configuration error naming where it was set, in every command (process took it).
  for (const char* command : {"run ", "process "}) {
    const RunResult key = run(command + sample() + " -o " + path("period.bin") + " --set engine.stats_period_s=1e-9 -q");
    EXPECT_EQ(key.exit_code, 2) << command << key.output;
    EXPECT_TRUE(has(key, "engine.stats_period_s = 1e-09 (set at --set engine.stats_period_s=1e-9) must be 0 (no "
                         "progress lines) or at least 1e-06 (1 us; from 5e-07 it rounds to 1 us)"))
        << command << key.output;
  }
  EXPECT_EQ(run("run " + sample() + " --set engine.stats_period_s=0.6e-6 -q").exit_code, 0);
}

// The sensor by one rule in every command: the size the file states, else
// --sensor, else estimator.sensor where the configuration sets it, else the
// data's. run, render and eval ignored a configured estimator.sensor (run's
// output then differed from process's), and run and eval said nothing of a
// --sensor the file's stated size overrode.
TEST_F(CliFlags, EveryCommandTakesTheSensorByOneRule) {
  const RunResult half = run("process " + sample() + " -o " + path("half.bin") + " --set estimator.sensor.width=300");
  EXPECT_EQ(half.exit_code, 2) << half.output;
  EXPECT_TRUE(has(half, "estimator.sensor.width is set at --set estimator.sensor.width=300, estimator.sensor.height is not"))
      << half.output;
  const std::string small = " --set estimator.sensor.width=64 --set estimator.sensor.height=64";
  for (const std::string& command : {"process " + sample() + " -o " + path("a.bin"), "run " + sample() + " -o " + path("b.bin"),
                                     "render " + sample() + " -o " + path("c.png") + " --at 0.2",
                                     "eval " + sample() + " -o " + path("ev")}) {
    const RunResult r = run(command + small + " -q");
    EXPECT_EQ(r.exit_code, 3) << command << ": " << r.output;
    EXPECT_TRUE(has(r, "is outside the 64x64 sensor")) << command << ": " << r.output;
  }
  const std::string wide = " --set estimator.sensor.width=200 --set estimator.sensor.height=150 -q";
  ASSERT_EQ(run("process " + sample() + " -o " + path("p.bin") + wide).exit_code, 0);
  ASSERT_EQ(run("run " + sample() + " -o " + path("r.bin") + wide).exit_code, 0);
  EXPECT_TRUE(evlife::test::read_text_file(path("p.bin")) == evlife::test::read_text_file(path("r.bin")));
  const std::string stated = path("stated.h5");  // synth's HDF5 states its 128 x 128
  ASSERT_EQ(run("synth -q --scene edges --duration 20ms -o " + stated).exit_code, 0);
  for (const std::string& command : {"process " + stated + " -o " + path("a.bin"), "run " + stated + " -o " + path("b.bin"),
                                     "render " + stated + " -o " + path("c.png") + " --at 0.01",
                                     "eval " + stated + " -o " + path("ev")}) {
    const RunResult r = run(command + " --sensor 1x1 -q");
    EXPECT_EQ(r.exit_code, 0) << command << ": " << r.output;
    EXPECT_TRUE(has(r, "warning: --sensor 1x1 ignored: ")) << command << ": " << r.output;
    EXPECT_TRUE(has(r, " states 128x128")) << command << ": " << r.output;
  }
}

// convert took --sensor only for a recording that states none: a stated
// size silently won, and evlife's own output (an augmented CSV states none)
// dropped it, checking nothing and storing no size in its HDF5.
TEST_F(CliFlags, ConvertTakesTheSensorAsTheOtherCommands) {
  const std::string stated = path("stated.h5");  // synth's HDF5 states its 128 x 128
  ASSERT_EQ(run("synth -q --scene edges --duration 20ms -o " + stated).exit_code, 0);
  for (const std::string unchecked : {"", " --unchecked"}) {
    const RunResult ignored = run("convert " + stated + " " + path("x.txt") + " --sensor 1x1 -q" + unchecked);
    EXPECT_EQ(ignored.exit_code, 0) << ignored.output;
    EXPECT_TRUE(has(ignored, "warning: --sensor 1x1 ignored: " + stated + " states 128x128")) << ignored.output;
  }
  ASSERT_EQ(run("process " + stated + " -o " + path("a.csv") + " -q").exit_code, 0);
  ASSERT_EQ(run("convert " + path("a.csv") + " " + path("b.h5") + " --sensor 300x200 -q").exit_code, 0);
  const RunResult info = run("info " + path("b.h5"));
  EXPECT_TRUE(has(info, "300x200 (stated by the file)")) << info.output;
  for (const std::string out : {"c.h5", "c.txt", "c.bin"}) {
    const RunResult small = run("convert " + path("a.csv") + " " + path(out) + " --sensor 4x4 -q");
    EXPECT_EQ(small.exit_code, 3) << out << ": " << small.output;
    EXPECT_TRUE(has(small, "is outside the 4x4 sensor (event index ")) << out << ": " << small.output;
  }
  const RunResult flags = run("convert " + path("a.csv") + " " + path("d.txt") + " --unchecked --one-thread -q");
  EXPECT_EQ(flags.exit_code, 0) << flags.output;
  EXPECT_TRUE(has(flags, "warning: --unchecked and --one-thread ignored: ")) << flags.output;
}

// Accepted and ignored before: the estimator's settings for lifetimes that a
// file already holds, lifetime colours where none are drawn, thinning of
// fixed windows. Refused; where they act, they still change the frame.
TEST_F(CliFlags, RenderAndEvalRefuseFlagsThatWouldChangeNothing) {
  const std::string in = sample();
  ASSERT_EQ(run("process " + in + " -o " + path("a.bin") + " -q").exit_code, 0);
  for (const std::string& command :
       {"render " + path("a.bin") + " -o " + path("k.png") + " --at 0.2 --set estimator.window_size=7",
        "eval " + path("a.bin") + " -o " + path("ev") + " --set estimator.regularization=false"}) {
    const RunResult r = run(command + " -q");
    EXPECT_EQ(r.exit_code, 2) << command << ": " << r.output;
    EXPECT_TRUE(has(r, "--set estimator.")) << r.output;
    EXPECT_TRUE(has(r, ": nothing to estimate in " + path("a.bin"))) << r.output;
  }
  const RunResult colours = run("render " + in + " -o " + path("c.png") + " --at 0.2 --color polarity --lifetime-range 1:10 -q");
  EXPECT_EQ(colours.exit_code, 2) << colours.output;
  EXPECT_TRUE(has(colours, "--lifetime-range sets the lifetime colours: --mode lifetime --color polarity draws none"))
      << colours.output;
  const RunResult thin = run("render " + in + " -o " + path("w.png") + " --at 0.2 --mode window:30ms --no-thinning -q");
  EXPECT_EQ(thin.exit_code, 2) << thin.output;
  EXPECT_TRUE(has(thin, "--no-thinning: --mode window:30ms draws no lifetime image to thin")) << thin.output;
  // A --config file's estimator keys: said, not refused (one file often
  // configures every command); estimator.sensor.* still applies.
  {
    std::ofstream(path("dim.yaml")) << "estimator:\n  max_lifetime_standard_error: 0.5\n";
    const RunResult r = run("render " + path("a.bin") + " -o " + path("k.png") + " --at 0.2 -q --config " + path("dim.yaml"));
    EXPECT_EQ(r.exit_code, 0) << r.output;
    EXPECT_TRUE(has(r, "warning: estimator.max_lifetime_standard_error of --config ignored: nothing to estimate in"))
        << r.output;
    // --print-config's file given back restates the defaults: nothing to say.
    const RunResult printed = run("process --print-config");
    std::ofstream(path("printed.yaml")) << printed.output;
    const RunResult same = run("render " + path("a.bin") + " -o " + path("k.png") + " --at 0.2 -q --config " + path("printed.yaml"));
    EXPECT_EQ(same.exit_code, 0) << same.output;
    EXPECT_FALSE(has(same, "warning")) << same.output;
  }
  // Where they act: the compare mode's lifetime panel.
  ASSERT_EQ(run("render " + in + " -o " + path("c1.png") + " --at 0.2 --mode compare -q").exit_code, 0);
  ASSERT_EQ(run("render " + in + " -o " + path("c2.png") + " --at 0.2 --mode compare --no-thinning -q").exit_code, 0);
  ASSERT_EQ(run("render " + in + " -o " + path("c3.png") + " --at 0.2 --mode compare --lifetime-range 1:10 -q").exit_code,
            0);
  const std::string plain = evlife::test::read_text_file(path("c1.png"));
  EXPECT_NE(plain, evlife::test::read_text_file(path("c2.png")));
  EXPECT_NE(plain, evlife::test::read_text_file(path("c3.png")));
}

// A recording that states no sensor, with one event beyond any camera: the
// sensor scan names it (render, eval and run said only "sensor.width: 5001
// must be in [1, 4096]"; process that the sensor was "not usable").
TEST_F(CliFlags, AnEventBeyondAnyCameraIsNamedByTheSensorScan) {
  const std::string in = path("wide.txt");
  std::ofstream(in) << "0.000001 1 1 1\n0.000002 2 2 0\n0.000003 5000 3 1\n0.000004 4 4 1\n";
  for (const std::string& command : {"process " + in + " -o " + path("a.bin"), "render " + in + " -o " + path("r.png") +
                                     " --at 0", "eval " + in + " -o " + path("ev"), "run " + in + " -o " + path("b.bin")}) {
    const RunResult r = run(command + " -q");
    EXPECT_EQ(r.exit_code, 3) << command << ": " << r.output;
    EXPECT_TRUE(has(r, in + ": event at (x 5000, y 3) is beyond any camera (at most 4096 px a side) and the file states "
                        "no sensor"))
        << command << ": " << r.output;
    EXPECT_TRUE(has(r, "(event index 2)")) << command << ": " << r.output;
  }
}

// A rule across two keys names where each was set (it named neither), and
// eval checks the configuration for each N it runs: one valid for the
// configured N only stopped it half-way, as an input error, writing nothing.
TEST_F(CliFlags, ARuleAcrossKeysNamesBothAndEvalChecksEveryWindowSize) {
  const std::string in = sample();
  std::ofstream(path("cms.yaml")) << "estimator:\n  window_size: 3\n  continuation_min_support: 6\n";
  const RunResult r = run("process " + in + " -o " + path("x.csv") + " --config " + path("cms.yaml"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(has(r, "(estimator.continuation_min_support set at " + path("cms.yaml") +
                         ":3; estimator.window_size set at " + path("cms.yaml") + ":2)"))
      << r.output;
  ASSERT_EQ(run("process " + in + " -o " + path("y.csv") + " -q --set estimator.continuation_min_support=12").exit_code, 0);
  const RunResult e = run("eval " + in + " -o " + path("ev") + " -q --set estimator.continuation_min_support=12");
  EXPECT_EQ(e.exit_code, 2) << e.output;
  EXPECT_TRUE(has(e, "eval runs N = 3, 5 and 7 with the rest of the configuration; with window_size 3, "
                     "estimator.continuation_min_support: 12 must be 0 or in 2..")) << e.output;
}

// synth's two outputs in one file by another spelling (./a.txt, a link, a
// link to a file not yet there) interleaved the truth with the events; a
// background that cannot fit in memory is refused before it is generated,
// by synth and by run's synth: sources.
TEST_F(CliFlags, SynthRefusesOutputsThatCollideAndScenesThatCannotFit) {
  const std::string events = path("a.txt");
  fs::create_symlink(events, path("link.txt"));
  fs::create_symlink(path("later.txt"), path("dangling.txt"));
  for (const auto& [out, truth] : std::vector<std::pair<std::string, std::string>>{
           {events, dir_.path().string() + "/./a.txt"}, {path("link.txt"), events},
           {path("dangling.txt"), path("later.txt")}}) {
    const RunResult r = run("synth -q --duration 10ms -o " + out + " --truth " + truth);
    EXPECT_EQ(r.exit_code, 2) << out << " " << truth << ": " << r.output;
    EXPECT_TRUE(has(r, "--truth and -o name the same file")) << r.output;
  }
  EXPECT_FALSE(fs::exists(events));
  EXPECT_EQ(run("synth -q --duration 10ms -o " + events + " --truth " + path("truth.csv")).exit_code, 0);
  // The truth is CSV: under another format's name its readers refused it.
  const RunResult h5_truth = run("synth -q --duration 10ms -o " + path("b.txt") + " --truth " + path("truth.h5"));
  EXPECT_EQ(h5_truth.exit_code, 2) << h5_truth.output;
  EXPECT_TRUE(has(h5_truth, "the ground truth is written as CSV; name it .csv")) << h5_truth.output;
  EXPECT_FALSE(fs::exists(path("b.txt")));
  const RunResult noise = run("synth -q --noise-rate 10000 --sensor 4096x4096 --duration 1 -o " + path("n.txt"));
  EXPECT_EQ(noise.exit_code, 2) << noise.output;
  EXPECT_TRUE(has(noise, "the scene's background activity and hot pixels need ")) << noise.output;
  EXPECT_TRUE(has(noise, "of memory available (for each generation slice): lower --noise-rate or the sensor"))
      << noise.output;
  EXPECT_FALSE(fs::exists(path("n.txt")));
  const RunResult texture = run("run synth:textured --sensor 4096x4096 --duration 3600 -q");
  EXPECT_EQ(texture.exit_code, 2) << texture.output;
  EXPECT_TRUE(has(texture, "(the textured scene is generated whole): lower --noise-rate, the sensor or --duration"))
      << texture.output;
}

// One timestamp far ahead (a corrupt clock) asked for millions of blank
// frames at --fps; render draws up to the gap and stops with an input
// error (exit 3) unless --to asks for them.
TEST_F(CliFlags, RenderStopsBeforeAnHourOfBlankFrames) {
  const std::string outlier = path("outlier.txt");
  {
    std::ofstream text(outlier);
    for (int i = 0; i < 3000; ++i) text << 1e-4 * i << " " << i % 40 << " " << i % 30 << " " << i % 2 << "\n";
    text << "100000 5 5 1\n";
  }
  const RunResult r = run("render " + outlier + " -q -o " + path("frames") + " --fps 30");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_TRUE(has(r, "empty frames at 30 fps come first; a timestamp outlier? Stopped before them")) << r.output;
  std::size_t frames = 0;
  for ([[maybe_unused]] const auto& f : fs::directory_iterator(path("frames"))) ++frames;
  // 0 .. 0.3 s at 30 fps: the frame at 0.3 s shows the last events (0.2999 s), the empty ones begin at 0.333 s.
  EXPECT_EQ(frames, 10u);
  EXPECT_EQ(run("render " + outlier + " -q -o " + path("frames_to") + " --fps 30 --to 1").exit_code, 0);
}

// A stretch without events (a timestamp outlier, hours ahead) had a paced
// replay wait it out in silence, its progress at 100 %: each is said before
// the wait, -q or not (as render's gaps). 120 s at --realtime=1000: 0.12 s.
TEST_F(CliFlags, RealtimeRunSaysEachLongGapBeforeWaitingItOut) {
  const std::string gaps = path("gaps.txt");
  {
    std::ofstream text(gaps);
    text << "0 1 1 1\n0.0005 2 2 0\n0.001 3 3 1\n120 4 4 1\n120.0005 5 5 0\n240 6 6 1\n";
  }
  const RunResult r = run("run " + gaps + " --realtime=1000 -q -o " + path("rt.bin"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(has(r, "warning: the replay waits 0.12 s (120 s of recording time x 1/1000) for the next event at t = "
                     "120000000 us (none since t = 1000 us): a gap in the recording; Ctrl-C stops"))
      << r.output;
  EXPECT_TRUE(has(r, "for the next event at t = 240000000 us (none since t = 120000500 us)")) << r.output;
  std::size_t said = 0;
  for (std::size_t at = r.output.find("a gap in the recording"); at != std::string::npos;
       at = r.output.find("a gap in the recording", at + 1))
    ++said;
  EXPECT_EQ(said, 2u) << r.output;  // once per gap, not once per wake-up of the wait
  const RunResult unpaced = run("run " + gaps + " -q -o " + path("fast.bin"));
  EXPECT_EQ(unpaced.exit_code, 0) << unpaced.output;
  EXPECT_FALSE(has(unpaced, "a gap in the recording")) << unpaced.output;  // nothing is waited for
}

}  // namespace

namespace {

// An option given under two of its names says so (it named only the second).
TEST_F(CliFlags, AnOptionUnderTwoNamesIsNamedBoth) {
  const RunResult r = run("eval " + sample() + " -o " + path("ev") + " --at 0.2 --frame-at 0.3");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(has(r, "'--at' and '--frame-at' are the same option: give it once")) << r.output;
  EXPECT_TRUE(has(run("process " + sample() + " -o a.csv -o b.csv"), "option '-o' given more than once"));
}

// synth's HDF5 output states the scene's sensor, as convert's does: a scene
// whose events do not reach its right and bottom borders read back with the
// sensor it was made on (before: "not stated", the span of the events).
TEST_F(CliFlags, SynthesizedHdf5StatesItsSensor) {
  const std::string h5 = path("wide.h5");
  ASSERT_EQ(run("synth -q --scene bar --sensor 400x90 --duration 20ms -o " + h5).exit_code, 0);
  const RunResult r = run("info " + h5);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(has(r, "sensor     400x90 (stated by the file)")) << r.output;
}

// What a review found accepted without a word: a --polarity that selects
// nothing (a file of OFF events only, --polarity on: exit 0, 0 events, no
// warning; render said the file "holds no event"), render -q leaving most
// events out of its frames (the count was in the summary, which -q skips),
// run --fps 0 without --at (no frame drawn, exit 0) and more --workers than
// tiles (idle workers holding an estimator's memory each), an engine key set
// for process.
TEST_F(CliFlags, SelectionsAndFlagsThatCanDoNothingAreSaid) {
  const std::string off = path("off.txt");
  {
    std::ofstream f(off);
    for (int i = 0; i < 200; ++i) f << 0.001 * i << ' ' << i % 20 << ' ' << i % 10 << " 0\n";
  }
  for (const char* command : {"process", "run"}) {
    const RunResult r = run(std::string(command) + " " + off + " --sensor 32x32 --polarity on -o " + path("on.bin"));
    EXPECT_EQ(r.exit_code, 0) << r.output;
    EXPECT_TRUE(has(r, "warning: no event of " + off + " is ON (--polarity on)")) << command << r.output;
  }
  const RunResult c = run("convert " + off + " --polarity on -o " + path("on.txt"));
  EXPECT_TRUE(has(c, "warning: no event of " + off + " is ON (--polarity on)")) << c.output;
  const RunResult rendered = run("render " + off + " --sensor 32x32 --polarity on --at 0.05 -o " + path("on.png"));
  EXPECT_EQ(rendered.exit_code, 3) << rendered.output;
  EXPECT_TRUE(has(rendered, "no event of " + off + " is ON (--polarity on): nothing to draw")) << rendered.output;
  EXPECT_FALSE(has(rendered, "holds no event")) << rendered.output;

  const RunResult p = run("process " + sample() + " -o " + path("all.csv") + " -q");
  ASSERT_EQ(p.exit_code, 0) << p.output;
  const RunResult quiet = run("render " + path("all.csv") + " --sensor 16x16 -q --at 0.1 -o " + path("corner.png"));
  EXPECT_EQ(quiet.exit_code, 0) << quiet.output;
  EXPECT_TRUE(has(quiet, "evlife render: warning: not drawn: ")) << quiet.output;
  EXPECT_TRUE(has(quiet, " outside the sensor")) << quiet.output;

  const RunResult no_frame = run("run " + sample() + " --frames " + path("frames") + " --fps 0 -q");
  EXPECT_EQ(no_frame.exit_code, 2) << no_frame.output;
  EXPECT_TRUE(has(no_frame, "--fps 0 draws only the --at instants, and none is given")) << no_frame.output;
  const RunResult idle = run("run " + sample() + " --workers 3 -q");
  EXPECT_EQ(idle.exit_code, 2) << idle.output;
  EXPECT_TRUE(has(idle, "--workers 3: --tiles 1x1 makes 2 tiles")) << idle.output;
  // The same count from the configuration (it ran, 30 idle workers holding an estimator each).
  std::ofstream(path("w32.yaml")) << "engine:\n  workers: 32\n";
  for (const std::string& from : {std::string("--set engine.workers=32"), "--config " + path("w32.yaml")}) {
    const RunResult configured = run("run " + sample() + " " + from + " -q");
    EXPECT_EQ(configured.exit_code, 2) << from << "\n" << configured.output;
    EXPECT_TRUE(has(configured, "engine.workers = 32 (--set or --config): --tiles 1x1 makes 2 tiles")) << configured.output;
  }
  EXPECT_EQ(run("run " + sample() + " --workers 8 --tiles 2x2 -q -o " + path("eight.bin")).exit_code, 0);
  // An engine key set for a command that runs no engine (it was range-checked, then ignored).
  const RunResult engine_key = run("process " + sample() + " --set engine.workers=32 -q -o " + path("e.bin"));
  EXPECT_EQ(engine_key.exit_code, 2) << engine_key.output;
  EXPECT_TRUE(has(engine_key, "--set engine.workers=32: engine settings are `evlife run`'s")) << engine_key.output;
  // The key as --set reads it (blanks dropped): a leading blank passed the refusal, then the setting was ignored.
  const RunResult blank_key = run("process " + sample() + " --set ' engine.workers=32' -q -o " + path("e.bin"));
  EXPECT_EQ(blank_key.exit_code, 2) << blank_key.output;
  EXPECT_TRUE(has(blank_key, "engine settings are `evlife run`'s")) << blank_key.output;
}

// Every command given a named pipe names the pipe as given in its messages:
// the warning that --sensor is ignored (the text states its size) and the
// error of a time going back. Before, they named the pipe's temporary copy
// (`$TMPDIR/evlife-Ab12Cd/rec.txt: timestamp goes backwards`), which the user
// never typed and which is gone when they read it.
TEST_F(CliFlags, EveryCommandNamesANamedPipeAsGivenNotItsCopy) {
  const fs::path tmp = path("tmp");
  fs::create_directories(tmp);
  const std::string fifo = path("rec.txt");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string stated = " --sensor 64x64 -q";  // ignored: the text states 240x180
  for (const std::string& command :
       {"process '" + fifo + "' -o " + path("a.csv") + stated, "run '" + fifo + "' -o " + path("b.bin") + stated,
        "render '" + fifo + "' -o " + path("c.png") + " --at 0.000002" + stated,
        "eval '" + fifo + "' -o " + path("ev") + stated, "convert '" + fifo + "' " + path("d.txt") + stated,
        "info '" + fifo + "'"}) {
    const std::string script = path("fifo.sh");
    std::ofstream(script) << "export TMPDIR='" << tmp.string() << "'\n"
                          << "printf '240 180\\n0.000001 1 1 1\\n0.000003 2 2 0\\n0.000002 3 2 1\\n' > '" << fifo << "' &\n"
                          << "timeout -k 5 60 '" << kCli << "' " << command << "\n";
    const RunResult r = evlife::test::run_cli("/bin/sh", "'" + script + "'", dir_.path() / "fifo.log");
    EXPECT_EQ(r.exit_code, 3) << command << ": " << r.output;
    EXPECT_TRUE(has(r, fifo + ": timestamp goes backwards")) << command << ": " << r.output;
    if (command.find(stated) != std::string::npos) {
      EXPECT_TRUE(has(r, "--sensor 64x64 ignored: " + fifo + " states 240x180")) << command << ": " << r.output;
    }
    EXPECT_FALSE(evlife::test::names_a_stream_copy(r.output, tmp)) << command << ": " << r.output;
  }
  EXPECT_TRUE(fs::is_empty(tmp)) << "a copy was left in " << tmp;
}

}  // namespace

namespace {

// A render mode or colour the render library refuses names the flag it came
// in, in render as in run (render said only `window must be longer than 0 in
// 'window:0'` and `unknown colour mode 'bogus'`).
TEST_F(CliFlags, ARefusedModeOrColourNamesItsFlag) {
  const std::string in = two_events();
  const std::string render = "render " + in + " --sensor 8x8 -o " + path("f.png") + " --at 0";
  for (const auto& [flags, message] :
       {std::pair{" --mode window:0", "evlife render: --mode window must be longer than 0 in 'window:0'"},
        std::pair{" -m window:0", "evlife render: --mode window must be longer than 0 in 'window:0'"},
        std::pair{" --color bogus", "evlife render: --color unknown colour mode 'bogus' (use lifetime"}}) {
    const RunResult r = run(render + flags);
    EXPECT_EQ(r.exit_code, 2) << flags << ": " << r.output;
    EXPECT_TRUE(has(r, message)) << flags << ": " << r.output;
    EXPECT_TRUE(has(r, "(see evlife render --help)")) << flags << ": " << r.output;
  }
  const RunResult r = run("run " + in + " --sensor 8x8 --frames " + path("fr") + " --mode window:0");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(has(r, "evlife run: --mode window must be longer than 0 in 'window:0'")) << r.output;
}

// eval's --frame-at, also spelled --at, is named in its errors as it was typed
// (`--at 0.1,0.2` was called `--frame-at 0.1,0.2`).
TEST_F(CliFlags, AnOptionsErrorNamesItAsTyped) {
  const std::string in = two_events();
  const std::string eval = "eval " + in + " --sensor 8x8 -o " + path("ev");
  const RunResult at = run(eval + " --at 0.1,0.2");
  EXPECT_EQ(at.exit_code, 2) << at.output;
  EXPECT_TRUE(has(at, "evlife eval: --at 0.1,0.2: expected")) << at.output;
  EXPECT_FALSE(has(at, "--frame-at")) << at.output;
  const RunResult inline_at = run(eval + " --at=x");
  EXPECT_TRUE(has(inline_at, "evlife eval: --at x: expected")) << inline_at.output;
  const RunResult frame_at = run(eval + " --frame-at x");
  EXPECT_EQ(frame_at.exit_code, 2) << frame_at.output;
  EXPECT_TRUE(has(frame_at, "evlife eval: --frame-at x: expected")) << frame_at.output;
}

// An empty entry of an --at list is a usage error naming it, in render and
// run (`--at 0.5,,0.6` drew 0.5 and 0.6 without a word of the gap).
TEST_F(CliFlags, AnEmptyEntryOfAnInstantListIsRefused) {
  const std::string in = two_events();
  for (const std::string& command :
       {"render " + in + " --sensor 8x8 -o " + path("fr"), "run " + in + " --sensor 8x8 --frames " + path("fr")}) {
    const std::string name = command.substr(0, command.find(' '));
    for (const auto& [list, message] : {std::pair{"0.5,,0.6", "--at 0.5,,0.6: entry 2 of 3 is empty"},
                                        std::pair{"0.5,", "--at 0.5,: entry 2 of 2 is empty"},
                                        std::pair{",0.5", "--at ,0.5: entry 1 of 2 is empty"}}) {
      const RunResult r = run(command + " --at " + list);
      EXPECT_EQ(r.exit_code, 2) << command << " --at " << list << ": " << r.output;
      EXPECT_TRUE(has(r, "evlife " + name + ": " + message)) << command << " --at " << list << ": " << r.output;
      EXPECT_TRUE(has(r, "(see evlife " + name + " --help)")) << r.output;
    }
    EXPECT_TRUE(has(run(command + " --at ''"), "evlife " + name + ": --at: no time given"));
  }
  EXPECT_FALSE(fs::exists(path("fr")));
}

}  // namespace

namespace {

// --at instants on the same microsecond (as written, or rounded to it) are
// drawn once, and now said so (four asked, two frames, no word before).
TEST_F(CliFlags, RepeatedAtInstantsAreSaidToBeDrawnOnce) {
  const RunResult r = run("render " + sample() + " --at 0.0000012,0.0000014,0.1,100ms --frames " + path("at"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(has(r, "note: --at: 2 of its 4 instants repeat a microsecond already given")) << r.output;
  std::size_t frames = 0;
  for (const auto& entry : fs::directory_iterator(path("at"))) frames += entry.path().extension() == ".png";
  EXPECT_EQ(frames, 2u);
  const RunResult distinct = run("render " + sample() + " --at 0.1,0.2 --frames " + path("at2"));
  EXPECT_FALSE(has(distinct, "repeat a microsecond")) << distinct.output;
}

}  // namespace
