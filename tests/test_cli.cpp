// `evlife process` run as a user would (the built binary, EVLIFE_CLI_PATH):
// help, exit codes, messages naming the file, the events before a fault
// flushed to the output, one output row per input event, --set in effect.
// Expected counts come from decoding the inputs here, independently.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "scratch_dir.h"

namespace {

namespace fs = std::filesystem;

const std::string kCli = EVLIFE_CLI_PATH;
const std::string kData = EVLIFE_SHARED_DATA_DIR;
const std::string kRpgText = kData + "/rpg_txt/slider_depth_events_chunk.txt";
const std::string kAedat2 = kData + "/aedat2/alex_walking_again.aedat";

using RunResult = evlife::test::CliRun;

std::string read_file(const fs::path& path) { return evlife::test::read_text_file(path); }

class CliTest : public testing::Test {
 protected:
  // Runs `evlife <args>` through the shell, capturing both streams.
  RunResult run(const std::string& args) const { return evlife::test::run_cli(kCli, args, dir_.path() / "cli.log"); }
  RunResult expect_one_thread_changes_nothing(const std::string& command,
                                              std::initializer_list<const char*> exts,
                                              const std::string& fault_ext) const;

  fs::path path(const std::string& name) const { return dir_.path() / name; }

  const evlife::test::ScratchDir dir_{"test_cli"};
};

// Data rows of a CSV written by evlife (all lines but the header).
std::vector<std::string> csv_rows(const fs::path& path) {
  std::ifstream in(path);
  std::vector<std::string> rows;
  std::string line;
  bool header = true;
  while (std::getline(in, line)) {
    if (header) {
      EXPECT_EQ(line, "x,y,t,p,lifetime,vx,vy,prediction_error");
      header = false;
      continue;
    }
    rows.push_back(line);
  }
  return rows;
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  for (std::size_t end; (end = s.find(sep, start)) != std::string::npos; start = end + 1) {
    parts.push_back(s.substr(start, end - start));
  }
  parts.push_back(s.substr(start));
  return parts;
}

// The first `n` lines of the RPG text sample (each one event), newline-terminated.
std::string rpg_lines(std::size_t n) {
  std::ifstream in(kRpgText);
  std::string out;
  std::string line;
  for (std::size_t i = 0; i < n && std::getline(in, line); ++i) out += line + "\n";
  return out;
}

TEST_F(CliTest, HelpTeachesAndExitsZero) {
  const RunResult r = run("process --help");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  for (const char* needle : {"Usage: evlife process", "--sensor", "--config", "--set",
                             "Example", "lifetime", "Exit status", ".yaml"}) {
    EXPECT_NE(r.output.find(needle), std::string::npos) << "help lacks '" << needle << "'";
  }
}

TEST_F(CliTest, MissingInputNamesTheFile) {
  const std::string missing = path("no_such_recording.aedat").string();
  const RunResult r = run("process '" + missing + "' -o '" + path("out.csv").string() + "'");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find(missing), std::string::npos) << r.output;
}

// A named pipe (no writer yet): refused at once, naming what to do, instead
// of waiting forever in open() or failing later with "Illegal seek".
// INPUT `-` (stdin) and a named pipe read as the file itself does: the stream
// is copied into $TMPDIR first (readers read a file's start again), and the
// copy is gone afterwards. Before, a pipe was refused ("save the stream to a
// file first") and `-` was a missing file.
TEST_F(CliTest, StdinAndNamedPipesReadAsTheFileDoes) {
  const fs::path tmp = path("tmp");
  fs::create_directories(tmp);
  const std::string fifo = path("events.fifo").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const fs::path script = path("pipes.sh");
  std::ofstream(script) << "export TMPDIR='" << tmp.string() << "'\n"
                        << "cat '" << kRpgText << "' | timeout 60 '" << kCli << "' process - -o '"
                        << path("stdin.csv").string() << "' -q || exit 11\n"
                        << "cat '" << kRpgText << "' > '" << fifo << "' &\n"
                        << "timeout 60 '" << kCli << "' process '" << fifo << "' -o '" << path("fifo.csv").string()
                        << "' -q || exit 12\n"
                        << "cat '" << kRpgText << "' | timeout 60 '" << kCli << "' info - || exit 13\n";
  const RunResult r = evlife::test::run_cli("/bin/sh", "'" + script.string() + "'", dir_.path() / "pipes.log");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ASSERT_EQ(run("process '" + kRpgText + "' -o '" + path("file.csv").string() + "' -q").exit_code, 0);
  const std::string expected = evlife::test::read_text_file(path("file.csv"));
  ASSERT_FALSE(expected.empty());
  EXPECT_TRUE(evlife::test::read_text_file(path("stdin.csv")) == expected);
  EXPECT_TRUE(evlife::test::read_text_file(path("fifo.csv")) == expected);
  EXPECT_NE(r.output.find("file       stdin (a stream, read from its copy"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("events     50,000 ("), std::string::npos) << r.output;
  EXPECT_TRUE(fs::is_empty(tmp)) << "a copy was left in " << tmp;
  // evlife's .bin through stdin: told by its content (the copy has no extension).
  ASSERT_EQ(run("process '" + kRpgText + "' -o '" + path("file.bin").string() + "' -q").exit_code, 0);
  ASSERT_EQ(run("convert '" + path("file.bin").string() + "' -o '" + path("bin.csv").string() + "' -q").exit_code, 0);
  std::ofstream(script) << "cat '" << path("file.bin").string() << "' | '" << kCli << "' convert - -o '"
                        << path("stdin_bin.csv").string() << "' -q\n";
  const RunResult b = evlife::test::run_cli("/bin/sh", "'" + script.string() + "'", dir_.path() / "pipes.log");
  ASSERT_EQ(b.exit_code, 0) << b.output;
  EXPECT_TRUE(evlife::test::read_text_file(path("stdin_bin.csv")) == evlife::test::read_text_file(path("bin.csv")));
  // A fault in the stream is named as the stream's (`stdin`, not its
  // temporary copy: StdinIsNamedStdinNotItsCopy), and the copy is removed.
  std::ofstream(script) << "export TMPDIR='" << tmp.string() << "'\n"
                        << "printf '1 2 3 1\\n0.5 2 3 1\\n' | '" << kCli << "' process - -o '"
                        << path("backwards.csv").string() << "'\n";
  const RunResult fault = evlife::test::run_cli("/bin/sh", "'" + script.string() + "'", dir_.path() / "pipes.log");
  EXPECT_EQ(fault.exit_code, 3) << fault.output;
  EXPECT_NE(fault.output.find("input error: stdin: timestamp goes backwards"), std::string::npos) << fault.output;
  EXPECT_TRUE(fs::is_empty(tmp)) << "a copy was left in " << tmp;
}

// What was piped to stdin is named `stdin` in every message, as the user
// gave it: an error at open (no format), one after events (time going back)
// and a warning (a crop that selects nothing). Before, they named its
// temporary copy (`$TMPDIR/evlife-Ab12Cd/stdin: ...`), a path the user never
// typed and that is gone by the time they read it.
TEST_F(CliTest, StdinIsNamedStdinNotItsCopy) {
  const fs::path tmp = path("tmp");
  fs::create_directories(tmp);
  const std::string backwards = "printf '1 2 3 1\\n0.5 2 3 1\\n'";
  const std::string garbage = "printf '\\001\\002 not events'";
  const std::string csv = path("o.csv").string();
  struct Case {
    std::string feed, command, expected;
  };
  for (const Case& c : {Case{backwards, "process - -q -o '" + csv + "'", "input error: stdin: timestamp goes backwards"},
                        Case{backwards, "convert - '" + path("o.txt").string() + "' -q",
                             "input error: stdin: timestamp goes backwards"},
                        Case{backwards, "info -", "info: stdin: timestamp goes backwards"},
                        Case{garbage, "process - -q -o '" + csv + "'", "input error: stdin: "},
                        Case{"printf '1 2 3 1\\n'", "process - -q --from 10s -o '" + csv + "'",
                             "warning: no event of stdin within"}}) {
    const fs::path script = path("stdin.sh");
    std::ofstream(script) << "export TMPDIR='" << tmp.string() << "'\n"
                          << c.feed << " | timeout -k 5 60 '" << kCli << "' " << c.command << "\n";
    const RunResult r = evlife::test::run_cli("/bin/sh", "'" + script.string() + "'", dir_.path() / "stdin.log");
    EXPECT_NE(r.output.find(c.expected), std::string::npos) << c.command << ": " << r.output;
    EXPECT_FALSE(evlife::test::names_a_stream_copy(r.output, tmp)) << c.command << ": " << r.output;
  }
  EXPECT_TRUE(fs::is_empty(tmp)) << "a copy was left in " << tmp;
}

TEST_F(CliTest, UsageErrorsExitTwo) {
  EXPECT_EQ(run("process").exit_code, 2);
  EXPECT_EQ(run("process '" + kRpgText + "'").exit_code, 2);  // no -o
  EXPECT_EQ(run("process '" + kRpgText + "' -o out.txt").exit_code, 2);  // bad extension
  const RunResult unknown = run("process '" + kRpgText + "' -o x.csv --frobnicate");
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.output.find("--frobnicate"), std::string::npos) << unknown.output;
  const RunResult bad_sensor = run("process '" + kRpgText + "' -o x.csv --sensor 240by180");
  EXPECT_EQ(bad_sensor.exit_code, 2);
  EXPECT_NE(bad_sensor.output.find("240by180"), std::string::npos) << bad_sensor.output;
}

TEST_F(CliTest, BadConfigNamesKeyAndRange) {
  const RunResult out_of_range = run("process '" + kRpgText + "' -o '" + path("o.csv").string() +
                                     "' --set estimator.window_size=4");
  EXPECT_EQ(out_of_range.exit_code, 2);
  EXPECT_NE(out_of_range.output.find("estimator.window_size"), std::string::npos);
  EXPECT_NE(out_of_range.output.find("[3, 15]"), std::string::npos) << out_of_range.output;
  // Hex was read for every integer key: 0x7 ran a 7-pixel window.
  const RunResult hex = run("process '" + kRpgText + "' -o '" + path("o.csv").string() +
                            "' --set estimator.window_size=0x7");
  EXPECT_EQ(hex.exit_code, 2);
  EXPECT_NE(hex.output.find("--set estimator.window_size=0x7: estimator.window_size = '0x7' is not a valid integer"),
            std::string::npos)
      << hex.output;

  std::ofstream(path("bad.yaml")) << "estimator:\n  window_size: 5\n  colour: red\n";
  const RunResult unknown = run("process '" + kRpgText + "' -o '" + path("o.csv").string() +
                                "' --config '" + path("bad.yaml").string() + "'");
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.output.find("estimator.colour"), std::string::npos) << unknown.output;
  EXPECT_NE(unknown.output.find(path("bad.yaml").string() + ":3"), std::string::npos)
      << unknown.output;
}

TEST_F(CliTest, OneRowPerInputEventInInputOrder) {
  // 50,000 lines, one event each (PROVENANCE.md); count them here.
  std::size_t lines = 0;
  std::vector<std::string> first;
  {
    std::ifstream in(kRpgText);
    std::string line;
    while (std::getline(in, line)) {
      if (lines < 3) first.push_back(line);
      ++lines;
    }
  }
  ASSERT_EQ(lines, 50000u);
  const fs::path out = path("slider.csv");
  const RunResult r = run("process '" + kRpgText + "' -o '" + out.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto rows = csv_rows(out);
  EXPECT_EQ(rows.size(), lines);
  // Input fields unchanged: "t x y p" with t in s, p 0/1 -> "x,y,t_us,p(+1/-1)".
  for (std::size_t i = 0; i < first.size() && i < rows.size(); ++i) {
    const auto in = split(first[i], ' ');
    const auto row = split(rows[i], ',');
    ASSERT_EQ(row.size(), 8u) << rows[i];
    EXPECT_EQ(row[0], in[1]);
    EXPECT_EQ(row[1], in[2]);
    EXPECT_EQ(std::stoll(row[2]), std::llround(std::stod(in[0]) * 1e6));
    EXPECT_EQ(row[3], in[3] == "1" ? "1" : "-1");
  }
  // The summary reports the count and the noise share.
  EXPECT_NE(r.output.find("50000"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("labelled noise"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("p50"), std::string::npos) << r.output;
  // Not a terminal and a short run: no progress lines (CI logs stay clean).
  EXPECT_EQ(r.output.find("ETA"), std::string::npos) << r.output;
}

// "p50 6.53 ms" in the summary -> microseconds.
double summary_value_us(const std::string& output, const std::string& label) {
  const auto at = output.find(label + " ");
  if (at == std::string::npos) return -1;
  std::size_t used = 0;
  const std::string rest = output.substr(at + label.size() + 1);
  const double v = std::stod(rest, &used);
  const std::string unit = rest.substr(used + 1, 2);
  if (unit == "ms") return v * 1e3;
  return unit == "µ" ? v : v * 1e6;  // "µs" or "s"
}

TEST_F(CliTest, SummaryPercentilesMatchTheOutput) {
  const fs::path out = path("slider.csv");
  const RunResult r = run("process '" + kRpgText + "' -o '" + out.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::vector<double> lifetimes;
  std::vector<double> abs_errors;
  std::size_t noise = 0;
  const auto rows = csv_rows(out);
  for (const auto& row : rows) {
    const auto f = split(row, ',');
    const double lifetime = std::stod(f.at(4));
    if (lifetime > 0) lifetimes.push_back(lifetime); else ++noise;
    if (!f.at(7).empty()) abs_errors.push_back(std::fabs(std::stod(f[7])));
  }
  ASSERT_GT(lifetimes.size(), 100u);
  std::sort(lifetimes.begin(), lifetimes.end());
  for (const auto& [label, q] : {std::pair{"p10", 0.10}, {"p50", 0.50}, {"p90", 0.90}}) {
    const double expected = lifetimes[static_cast<std::size_t>(std::ceil(q * lifetimes.size())) - 1];
    const double reported = summary_value_us(r.output, label);
    // One log bin (1/100 decade, 2.3 %) plus the 3 significant digits printed.
    EXPECT_NEAR(reported, expected, 0.03 * expected) << label << "\n" << r.output;
  }
  // Median |prediction error| and the share below 10 ms (paper Fig. 9).
  ASSERT_GT(abs_errors.size(), 100u);
  std::sort(abs_errors.begin(), abs_errors.end());
  const double median = abs_errors[(abs_errors.size() + 1) / 2 - 1];
  EXPECT_NEAR(summary_value_us(r.output, "median"), median, 0.03 * median) << r.output;
  const double below = static_cast<double>(
      std::lower_bound(abs_errors.begin(), abs_errors.end(), 1e4) - abs_errors.begin());
  char share[32];
  std::snprintf(share, sizeof share, "%.1f %% below 10 ms", 100.0 * below / abs_errors.size());
  EXPECT_NE(r.output.find(share), std::string::npos) << share << "\n" << r.output;
  std::snprintf(share, sizeof share, "%.1f %%", 100.0 * static_cast<double>(noise) / rows.size());
  EXPECT_NE(r.output.find(std::string("labelled noise      ") + share), std::string::npos)
      << share << "\n" << r.output;
  // Why: the three reasons add up to the noise (no event is outside the sensor).
  unsigned long long few = 0, unsupported = 0, unresolved = 0;
  const std::size_t why = r.output.find("why noise");
  ASSERT_NE(why, std::string::npos) << r.output;
  ASSERT_EQ(std::sscanf(r.output.c_str() + why,
                        "why noise %llu few past events, %llu no plane with support, %llu fit unresolved", &few,
                        &unsupported, &unresolved),
            3)
      << r.output;
  EXPECT_EQ(few + unsupported + unresolved, noise) << r.output;
  EXPECT_GT(unsupported, 0u);
}

// A recording short against its lifetimes is partly warm-up (README,
// *Warm-up*): the summary says how many median lifetimes long it is. The
// slider chunk is 170 ms of ~9 ms lifetimes; stripes.mat (1.2 s of ~7 ms)
// is long enough to say nothing.
TEST_F(CliTest, ShortRecordingsSayHowManyLifetimesLongTheyAre) {
  const fs::path out = path("slider_warmup.csv");
  const RunResult r = run("process '" + kRpgText + "' -o '" + out.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::vector<double> lifetimes;
  double first_t_us = 0, last_t_us = 0;
  const auto rows = csv_rows(out);
  ASSERT_FALSE(rows.empty());
  for (const auto& row : rows) {
    const auto f = split(row, ',');
    last_t_us = std::stod(f.at(2));
    if (&row == &rows.front()) first_t_us = last_t_us;
    if (const double lifetime = std::stod(f.at(4)); lifetime > 0) lifetimes.push_back(lifetime);
  }
  ASSERT_GT(lifetimes.size(), 100u);
  std::sort(lifetimes.begin(), lifetimes.end());
  const double expected = (last_t_us - first_t_us) / lifetimes[(lifetimes.size() + 1) / 2 - 1];
  const std::size_t at = r.output.find("warm-up             the recording is ");
  ASSERT_NE(at, std::string::npos) << r.output;
  double reported = 0;
  ASSERT_EQ(std::sscanf(r.output.c_str() + at, "warm-up the recording is %lf", &reported), 1) << r.output;
  // The median from the summary's log histogram: one bin, 2.3 %.
  EXPECT_NEAR(reported, expected, 0.03 * expected) << r.output;

  const RunResult long_run =
      run("process '" + kData + "/reference/stripes.mat' -o '" + path("stripes_warmup.bin").string() + "'");
  ASSERT_EQ(long_run.exit_code, 0) << long_run.output;
  EXPECT_EQ(long_run.output.find("warm-up"), std::string::npos) << long_run.output;
}

// The summary names the pixels that fire at hot-pixel rates (>= 100 Hz over
// the recording) with their share of the events and of them labelled noise,
// counted here again from the output file: sample.aedat4 (a DVXplorer, 0.59 s)
// has tens of them (README, *Real background activity*), `evlife info` of
// the .bin and of the .csv (no sensor size: the span its events cover, here
// the whole 320x240) and `evlife run` say the same, stripes.mat has none, and
// the 170 ms slider is too short for the line.
TEST_F(CliTest, SummaryNamesThePixelsFiringAtHotPixelRates) {
  const fs::path out = path("aedat4_busy.csv");
  const RunResult r = run("process '" + kData + "/aedat4/sample.aedat4' -o '" + out.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  constexpr int kWidth = 320, kHeight = 240;
  std::vector<std::uint64_t> events(kWidth * kHeight), noise(kWidth * kHeight);
  const auto rows = csv_rows(out);
  ASSERT_FALSE(rows.empty());
  double first_t_us = 0, last_t_us = 0;
  for (const auto& row : rows) {
    const auto f = split(row, ',');
    const int i = std::stoi(f.at(1)) * kWidth + std::stoi(f.at(0));
    ++events.at(static_cast<std::size_t>(i));
    noise[static_cast<std::size_t>(i)] += std::stod(f.at(4)) == 0.0;
    last_t_us = std::stod(f.at(2));
    if (&row == &rows.front()) first_t_us = last_t_us;
  }
  const double span_s = (last_t_us - first_t_us) * 1e-6;
  std::uint64_t busy = 0, busy_events = 0, busy_noise = 0;
  std::size_t busiest = 0;
  for (std::size_t i = 0; i < events.size(); ++i) {
    if (events[i] > events[busiest]) busiest = i;
    if (static_cast<double>(events[i]) >= 100.0 * span_s) {
      ++busy;
      busy_events += events[i];
      busy_noise += noise[i];
    }
  }
  ASSERT_GE(busy, 10u);  // the recording's hot pixels
  char text[256];
  std::snprintf(text, sizeof text,
                "%llu of %d (busiest %.3g kHz at (%zu, %zu)): %.1f %% of the events, "
                "%.1f %% of theirs labelled noise",
                static_cast<unsigned long long>(busy), kWidth * kHeight,
                static_cast<double>(events[busiest]) / span_s / 1e3, busiest % kWidth, busiest / kWidth,
                100.0 * static_cast<double>(busy_events) / static_cast<double>(rows.size()),
                100.0 * static_cast<double>(busy_noise) / static_cast<double>(busy_events));
  const std::string line = std::string("pixels >= 100 Hz    ") + text;
  EXPECT_NE(r.output.find(line), std::string::npos) << line << "\n" << r.output;

  const fs::path bin = path("aedat4_busy.bin");
  ASSERT_EQ(run("process '" + kData + "/aedat4/sample.aedat4' -o '" + bin.string() + "' -q").exit_code, 0);
  const RunResult info = run("info '" + bin.string() + "'");
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_NE(info.output.find(line), std::string::npos) << line << "\n" << info.output;
  const RunResult info_csv = run("info '" + out.string() + "'");
  ASSERT_EQ(info_csv.exit_code, 0) << info_csv.output;
  EXPECT_NE(info_csv.output.find("the events span 320x240"), std::string::npos) << info_csv.output;
  EXPECT_NE(info_csv.output.find(line), std::string::npos) << line << "\n" << info_csv.output;
  // `evlife run` (the same estimator, evlife run == evlife process) counts the merged output.
  const RunResult live = run("run '" + kData + "/aedat4/sample.aedat4' -o '" + path("aedat4_run.bin").string() + "'");
  ASSERT_EQ(live.exit_code, 0) << live.output;
  EXPECT_NE(live.output.find(std::string("pixels : at >= 100 Hz ") + text), std::string::npos) << text << "\n"
                                                                                               << live.output;

  const RunResult stripes =
      run("process '" + kData + "/reference/stripes.mat' -o '" + path("stripes_busy.bin").string() + "'");
  ASSERT_EQ(stripes.exit_code, 0) << stripes.output;
  EXPECT_NE(stripes.output.find("pixels >= 100 Hz    none of 16384 (busiest "), std::string::npos)
      << stripes.output;
  const RunResult slider = run("process '" + kRpgText + "' -o '" + path("slider_busy.bin").string() + "'");
  ASSERT_EQ(slider.exit_code, 0) << slider.output;
  EXPECT_EQ(slider.output.find("pixels >= 100 Hz"), std::string::npos) << slider.output;
}

TEST_F(CliTest, BinaryOutputHasOneRecordPerEvent) {
  const fs::path out = path("slider.bin");
  const RunResult r = run("process '" + kRpgText + "' -o '" + out.string() + "' --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output, "");  // --quiet: nothing on success
  // 32-byte header + 32-byte records (README, "Binary augmented event format").
  EXPECT_EQ(fs::file_size(out), 32u + 32u * 50000u);
  // HDF5 output: written, and starts with the HDF5 signature.
  const fs::path h5 = path("slider.h5");
  ASSERT_EQ(run("process '" + kRpgText + "' -o '" + h5.string() + "' -q").exit_code, 0);
  EXPECT_EQ(read_file(h5).substr(0, 8), "\x89HDF\r\n\x1a\n");
  // An extension in capitals names the same format (the writers and Python took it, the
  // commands refused it).
  const fs::path upper = path("SLIDER.BIN");
  ASSERT_EQ(run("process '" + kRpgText + "' -o '" + upper.string() + "' -q").exit_code, 0);
  EXPECT_TRUE(read_file(upper) == read_file(out));
}

// By default the input is decoded ahead (and for process the output written
// behind) on threads of their own; --one-thread does all on one. The same
// bytes either way, also when the input breaks off: `command` on the sample
// to each extension, then on a file whose line 5001 is corrupt; returns the
// one-thread run's outcome on that file (its output: bad_one + fault_ext).
RunResult CliTest::expect_one_thread_changes_nothing(const std::string& command,
                                                     std::initializer_list<const char*> exts,
                                                     const std::string& fault_ext) const {
  for (const char* ext : exts) {
    const fs::path threaded = path(std::string("threaded") + ext), one = path(std::string("one") + ext);
    EXPECT_EQ(run(command + " '" + kRpgText + "' -o '" + threaded.string() + "' -q").exit_code, 0);
    EXPECT_EQ(run(command + " '" + kRpgText + "' -o '" + one.string() + "' -q --one-thread").exit_code, 0);
    EXPECT_GT(fs::file_size(one), 50000u) << command << ext;
    EXPECT_TRUE(read_file(threaded) == read_file(one)) << command << ext;
  }
  const fs::path bad = path("corrupt.txt");
  std::ofstream(bad) << rpg_lines(5000) << "not an event\n" << rpg_lines(100);
  const fs::path bad_threaded = path("bad_threaded" + fault_ext), bad_one = path("bad_one" + fault_ext);
  const RunResult threaded = run(command + " '" + bad.string() + "' -o '" + bad_threaded.string() + "' -q");
  const RunResult one = run(command + " '" + bad.string() + "' -o '" + bad_one.string() + "' -q --one-thread");
  EXPECT_EQ(threaded.exit_code, 3) << threaded.output;
  EXPECT_EQ(one.exit_code, 3) << one.output;
  std::string message = threaded.output;  // the same but for the output's name
  for (std::size_t at; (at = message.find("bad_threaded")) != std::string::npos;) message.replace(at, 12, "bad_one");
  EXPECT_EQ(message, one.output);
  EXPECT_TRUE(read_file(bad_threaded) == read_file(bad_one)) << command;
  return one;
}

TEST_F(CliTest, OneThreadAndOverlappedGiveTheSameBytes) {
  expect_one_thread_changes_nothing("process", {".csv", ".bin", ".h5"}, ".bin");
  EXPECT_EQ(fs::file_size(path("bad_one.bin")), 32u + 32u * 5000u);
}

TEST_F(CliTest, ConvertOnOneThreadWritesTheSameBytes) {
  const RunResult one = expect_one_thread_changes_nothing("convert", {".txt", ".h5"}, ".txt");
  EXPECT_NE(one.output.find("5000 events before the fault"), std::string::npos) << one.output;
}

TEST_F(CliTest, TruncatedRpgTextKeepsEventsBeforeTheFault) {
  const std::size_t good = 1234;
  const fs::path bad = path("truncated.txt");
  std::ofstream(bad) << rpg_lines(good) << "0.009125000 17";  // cut mid-line
  const fs::path out = path("truncated.csv");
  const RunResult r = run("process '" + bad.string() + "' -o '" + out.string() + "'");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find(bad.string()), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("event index " + std::to_string(good)), std::string::npos)
      << r.output;
  EXPECT_EQ(csv_rows(out).size(), good);
}

TEST_F(CliTest, CorruptLineInTheMiddleStopsThere) {
  const std::size_t good = 777;
  const fs::path bad = path("corrupt.txt");
  std::ofstream(bad) << rpg_lines(good) << "this is not an event\n" << rpg_lines(100);
  const fs::path out = path("corrupt.csv");
  const RunResult r = run("process '" + bad.string() + "' -o '" + out.string() + "'");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find(bad.string()), std::string::npos) << r.output;
  EXPECT_EQ(csv_rows(out).size(), good);
}

TEST_F(CliTest, TimestampGoingBackwardsIsAnError) {
  const std::size_t good = 500;
  const fs::path bad = path("backwards.txt");
  // Line 501 repeats line 1, whose time is earlier than line 500's.
  std::ofstream(bad) << rpg_lines(good) << rpg_lines(1);
  const fs::path out = path("backwards.csv");
  const RunResult r = run("process '" + bad.string() + "' -o '" + out.string() + "'");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("event index " + std::to_string(good)), std::string::npos)
      << r.output;
  EXPECT_EQ(csv_rows(out).size(), good);
}

TEST_F(CliTest, CoordinatesOutsideTheSensorAreAnError) {
  // DAVIS240 data (x up to 239) declared as a 128x128 sensor: the first event
  // with x or y >= 128 is the fault. Find it here.
  std::ifstream in(kRpgText);
  std::string line;
  std::size_t first_outside = 0;
  while (std::getline(in, line)) {
    const auto f = split(line, ' ');
    if (std::stoi(f[1]) >= 128 || std::stoi(f[2]) >= 128) break;
    ++first_outside;
  }
  const fs::path out = path("outside.csv");
  const RunResult r =
      run("process '" + kRpgText + "' --sensor 128x128 -o '" + out.string() + "'");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("event index " + std::to_string(first_outside)), std::string::npos)
      << r.output;
  EXPECT_EQ(csv_rows(out).size(), first_outside);
}

TEST_F(CliTest, SensorSetInTheConfigIsUsedWhenTheFormatIsSilent) {
  // Same fault as above, the 128x128 sensor coming from --set instead of --sensor.
  const std::string input = path("head.txt").string();
  std::ofstream(input) << rpg_lines(3000);
  const RunResult r = run("process '" + input + "' -o '" + path("o.csv").string() +
                          "' --set estimator.sensor.width=128 --set estimator.sensor.height=128");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("128x128"), std::string::npos) << r.output;
  // Without it the sensor is scanned from the data (the DAVIS240 events fit).
  const RunResult scanned = run("process '" + input + "' -o '" + path("o.csv").string() + "'");
  EXPECT_EQ(scanned.exit_code, 0) << scanned.output;
  EXPECT_NE(scanned.output.find("scanned from the data"), std::string::npos) << scanned.output;
  // Where the format states its size, the configuration's is ignored, and said so as --sensor's
  // (it was dropped without a word).
  const std::string evt3 = std::string(EVLIFE_SHARED_DATA_DIR) + "/evt3/evt3_sample.raw";
  for (const std::string command : {"process", "eval", "render"}) {
    const std::string out = command == "process" ? path("e.bin").string()
                            : command == "eval"  ? path("eval").string()
                                                 : path("r.png").string();
    const std::string extra = command == "render" ? " --at 0.004" : "";
    const RunResult stated = run(command + " '" + evt3 + "' -o '" + out + "'" + extra +
                                 " -q --set estimator.sensor.width=240 --set estimator.sensor.height=180");
    EXPECT_EQ(stated.exit_code, 0) << command << ": " << stated.output;
    EXPECT_NE(stated.output.find("warning: estimator.sensor 240x180 (--set estimator.sensor.height=180) ignored: "),
              std::string::npos)
        << command << ": " << stated.output;
  }
}

// AEDAT 2.0: '#' header lines, then big-endian (u32 address, u32 timestamp)
// records; address bit 15 marks a special (non-event) record.
struct Aedat2Layout {
  std::size_t header_bytes = 0;
  std::string bytes;
};

Aedat2Layout read_aedat2(const std::string& file) {
  Aedat2Layout a;
  a.bytes = read_file(file);
  std::size_t pos = 0;
  while (pos < a.bytes.size() && a.bytes[pos] == '#') {
    pos = a.bytes.find('\n', pos);
    if (pos == std::string::npos) break;
    ++pos;
  }
  a.header_bytes = pos;
  return a;
}

TEST_F(CliTest, TruncatedAedat2KeepsEventsBeforeTheFault) {
  const Aedat2Layout a = read_aedat2(kAedat2);
  ASSERT_EQ(a.header_bytes, 4612u);  // PROVENANCE.md
  const std::size_t records = 3000;
  std::size_t events = 0;  // non-special records among the first `records`
  for (std::size_t i = 0; i < records; ++i) {
    const auto* r = reinterpret_cast<const unsigned char*>(a.bytes.data() + a.header_bytes + 8 * i);
    const std::uint32_t address = (std::uint32_t{r[0]} << 24) | (std::uint32_t{r[1]} << 16) |
                                  (std::uint32_t{r[2]} << 8) | r[3];
    if ((address & 0x8000u) == 0) ++events;
  }
  ASSERT_GT(events, 0u);
  const fs::path bad = path("truncated.aedat");
  std::ofstream(bad, std::ios::binary) << a.bytes.substr(0, a.header_bytes + 8 * records + 5);
  const fs::path out = path("truncated.csv");
  const RunResult r = run("process '" + bad.string() + "' -o '" + out.string() + "'");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find(bad.string()), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("byte offset"), std::string::npos) << r.output;
  EXPECT_EQ(csv_rows(out).size(), events);
}

TEST_F(CliTest, UnwritableOutputExitsFour) {
  // Missing folders are created, so: a folder inside a regular file (ENOTDIR, even for root).
  std::ofstream(path("a_file")) << "x";
  const std::string out = path("a_file").string() + "/evlife/out.csv";
  const RunResult r = run("process '" + kRpgText + "' -o '" + out + "'");
  EXPECT_EQ(r.exit_code, 4) << r.output;
  EXPECT_NE(r.output.find(out + ": cannot create the folder " + path("a_file").string() + "/evlife: Not a directory"),
            std::string::npos) << r.output;
}

// A stop signal while the output's reader (a FIFO's) takes no data: the
// write gave up only when the reader left (exit 4, Broken pipe), deaf to
// Ctrl-C and SIGTERM; it gives up on the stop now, exit 130.
TEST_F(CliTest, AStopEndsAWriteToAFifoWhoseReaderTakesNothing) {
  const fs::path script = path("stalled_reader.sh");
  {
    std::ofstream sh(script);
    sh << "cd '" << dir_.path().string() << "'\n"
       << "for cmd in process run; do\n"
       << "  rm -f stalled.csv; mkfifo stalled.csv\n"
       << "  sleep 30 < stalled.csv & reader=$!\n"  // opens the FIFO, reads nothing
       << "  '" << kCli << "' $cmd '" << kData << "/reference/stripes.mat' -q -o stalled.csv & pid=$!\n"
       << "  sleep 1; kill -INT $pid; wait $pid; echo \"$cmd exit $?\"\n"
       << "  kill $reader 2>/dev/null\n"
       << "done\n";
  }
  const RunResult r = evlife::test::run_cli("sh", "'" + script.string() + "'", path("stalled.log"));
  EXPECT_NE(r.output.find("process exit 130"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("run exit 130"), std::string::npos) << r.output;
}

// A run that draws no frame leaves an existing video of that name as it was
// and says so (it said "frames : 0 written to v.mp4", the old video looking
// like the result).
TEST_F(CliTest, ARunWithoutFramesSaysItsVideoWasNotWritten) {
  std::ofstream(path("nothing.txt")).flush();
  std::ofstream(path("earlier.mp4")) << "an earlier video";
  const RunResult r = run("run '" + path("nothing.txt").string() + "' --sensor 240x180 --video '" +
                          path("earlier.mp4").string() + "'");
  EXPECT_NE(r.output.find("frames : none drawn: " + path("earlier.mp4").string() + " not written"), std::string::npos)
      << r.output;
  EXPECT_EQ(evlife::test::read_text_file(path("earlier.mp4")), "an earlier video");
}

// HDF5 seeks within its file: a FIFO is refused up front by name (it was
// "cannot create the HDF5 file (a full disk, or another program ...)").
TEST_F(CliTest, AnHdf5OutputOnAFifoIsRefusedAsNotARegularFile) {
  const fs::path fifo = path("fifo.h5");
  fs::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  const RunResult r = run("process '" + kRpgText + "' -q -o '" + fifo.string() + "'");
  EXPECT_EQ(r.exit_code, 4) << r.output;
  EXPECT_NE(r.output.find("fifo.h5: not a regular file"), std::string::npos) << r.output;
}

// --policy drop with -q: what was dropped is said (it went unsaid: -q skips
// the summary, and exit 0). Whether this machine drops is its own affair:
// the relation holds either way, in = written + the dropped said.
TEST_F(CliTest, DroppedEventsAreSaidEvenWhenQuiet) {
  const RunResult r = run("run '" + kRpgText + "' --policy drop --queue-batches 2 --batch-events 16 -q -o '" +
                          path("dropped.csv").string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::size_t in = 0;
  {
    std::ifstream text(kRpgText);
    for (std::string line; std::getline(text, line);) in += !line.empty() && line[0] != '#';
  }
  const std::size_t out = csv_rows(path("dropped.csv")).size();
  ASSERT_LE(out, in);
  if (out == in) {
    EXPECT_EQ(r.output.find("dropped"), std::string::npos) << r.output;
  } else {
    EXPECT_NE(r.output.find("warning: " + std::to_string(in - out) + " of " + std::to_string(in) + " events dropped"),
              std::string::npos) << r.output;
  }
}

// Every clock frame --policy drop leaves undrawn is said, with -q too: the
// frames written plus those said not drawn are the frames --policy block
// draws, whether this machine falls behind or not. (A bug hunt's finding:
// with -q nothing was said; and frames after the last event the workers
// passed on, when they dropped the recording's end, were counted nowhere:
// 1 frame of 35 written, the summary silent.)
TEST_F(CliTest, EveryFrameDropLeavesUndrawnIsSaidEvenWhenQuiet) {
  const auto frames_in = [](const fs::path& dir) {
    return fs::exists(dir) ? static_cast<std::size_t>(std::distance(fs::directory_iterator(dir), fs::directory_iterator{}))
                           : std::size_t{0};
  };
  const RunResult all = run("run '" + kRpgText + "' --frames '" + path("all").string() + "' --fps 200 -q");
  ASSERT_EQ(all.exit_code, 0) << all.output;
  const std::size_t due = frames_in(path("all"));
  ASSERT_GT(due, 10U);
  for (int round = 0; round < 3; ++round) {
    const fs::path dir = path("drop" + std::to_string(round));
    const RunResult r = run("run '" + kRpgText + "' --frames '" + dir.string() +
                            "' --fps 200 --policy drop --queue-batches 2 --batch-events 16 -q");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const std::size_t drawn = frames_in(dir);
    std::size_t said = 0;
    if (const std::size_t count_end = r.output.find(" frames due not drawn"); count_end != std::string::npos) {
      const std::size_t start = r.output.rfind("warning: ", count_end) + 9;
      said = std::stoul(r.output.substr(start, count_end - start));
    }
    EXPECT_EQ(drawn + said, due) << "round " << round << ": " << drawn << " drawn\n" << r.output;
  }
}

// `script` (sh, `$DISK` a 256 KiB tmpfs) in a private mount namespace; an
// empty result when this machine allows no such mount (the test skips).
std::optional<RunResult> run_on_a_small_disk(const fs::path& dir, const std::string& script) {
  const fs::path disk = dir / "small_disk";
  fs::create_directories(disk);
  {
    std::ofstream file(dir / "small_disk.sh");
    file << "DISK='" << disk.string() << "'\nmount -t tmpfs -o size=256k tmpfs \"$DISK\" || exit 77\n"
         << "echo mounted\n" << script;
  }
  // Root may make a mount namespace; others through a user namespace.
  const std::string flags = ::geteuid() == 0 ? "-m" : "-r -m";
  const RunResult r = evlife::test::run_cli("unshare", flags + " sh '" + (dir / "small_disk.sh").string() + "'",
                                            dir / "unshare.log");
  if (r.exit_code == 77 || r.output.find("mounted") == std::string::npos) return std::nullopt;
  return r;
}

// A disk that fills up under an HDF5 output: exit 4 naming the file and what
// it holds, and the file closes whole with the events before the fault.
// Before, libhdf5 1.10's failed close left a dangling file id and its exit
// handler crashed (SIGSEGV).
TEST_F(CliTest, AFullDiskUnderAnHdf5OutputIsAnOutputErrorAndTheFileStaysReadable) {
  const auto r = run_on_a_small_disk(dir_.path(), "'" + kCli + "' process '" + EVLIFE_SHARED_DATA_DIR +
                                                      "/reference/stripes.mat' -q -o \"$DISK/s.h5\"\n"
                                                      "echo \"process exit $?\"\n'" +
                                                      kCli + "' info \"$DISK/s.h5\"\n");
  if (!r) GTEST_SKIP() << "no private tmpfs mount here";
  EXPECT_NE(r->output.find("process exit 4"), std::string::npos) << r->output;
  EXPECT_NE(r->output.find("s.h5: the disk is nearly full"), std::string::npos) << r->output;
  EXPECT_NE(r->output.find("format     augmented-hdf5"), std::string::npos) << "the file reads back: " << r->output;
  EXPECT_EQ(r->exit_code, 0) << r->output;
}

// A video cut short by a full disk (OpenCV's writer reports nothing: an .mp4
// without its index, an .avi without its end) is an output error, not exit 0,
// said by evlife alone.
TEST_F(CliTest, AVideoCutShortByAFullDiskIsAnOutputError) {
  std::string script;
  for (const char* ext : {"mp4", "avi"})
    script += "'" + kCli + "' render '" + EVLIFE_SHARED_DATA_DIR + "/reference/stripes.mat' -q --fps 100 -o \"$DISK/v." +
              ext + "\"\necho \"" + ext + " exit $?\"\nrm -f \"$DISK/v." + ext + "\"\n";
  const auto r = run_on_a_small_disk(dir_.path(), script);
  if (!r) GTEST_SKIP() << "no private tmpfs mount here";
  for (const char* ext : {"mp4", "avi"}) {
    EXPECT_NE(r->output.find(std::string(ext) + " exit 4"), std::string::npos) << r->output;
    EXPECT_NE(r->output.find(std::string("v.") + ext + " is incomplete"), std::string::npos) << r->output;
  }
  // FFmpeg's own log of the check that reads the cut file back came first.
  EXPECT_EQ(r->output.find("moov atom not found"), std::string::npos) << r->output;
}

// A file named .bin is evlife's output: one without its magic is said to be
// that by every command that reads one (before: render and eval listed every
// format, convert asked for the CSV header, info listed every format), and a
// good one given to `process` says what reads it (before: "unknown format").
TEST_F(CliTest, ABinThatIsNotEvlifesIsNamedSoByEveryCommand) {
  const std::string good = path("good.bin").string();
  ASSERT_EQ(run("process '" + kRpgText + "' -o '" + good + "' -q").exit_code, 0);
  std::string bytes = evlife::test::read_text_file(good);
  ASSERT_GT(bytes.size(), 8u);
  bytes.replace(0, 8, "ZZZZZZZZ");
  const std::string bad = path("bad.bin").string();
  std::ofstream(bad, std::ios::binary) << bytes;
  const std::string said = bad + ": not evlife's .bin: it starts with 'ZZZZZZZZ'";
  for (const std::string& command : {"info '" + bad + "'", "convert '" + bad + "' -o '" + path("b.txt").string() + "'",
                                    "render '" + bad + "' -o '" + path("b.png").string() + "' --at 0.05",
                                    "eval '" + bad + "' -o '" + path("b_eval").string() + "'",
                                    "process '" + bad + "' -o '" + path("b.csv").string() + "'"}) {
    const RunResult r = run(command);
    EXPECT_EQ(r.exit_code, 3) << command << "\n" << r.output;
    EXPECT_NE(r.output.find(said), std::string::npos) << command << "\n" << r.output;
    EXPECT_EQ(r.output.find("known formats"), std::string::npos) << command << "\n" << r.output;
  }
  const RunResult again = run("process '" + good + "' -o '" + path("again.csv").string() + "'");
  EXPECT_EQ(again.exit_code, 3) << again.output;
  EXPECT_NE(again.output.find(good + ": evlife's output (.bin: its events carry lifetimes already)"), std::string::npos)
      << again.output;
}

// A review helper's finding: evlife's augmented CSV with one header byte
// changed ("lifetimf") read as a plain CSV (other columns ignored): convert
// wrote its events without lifetimes and eval estimated them again, exit 0.
TEST_F(CliTest, AnAugmentedCsvWithADamagedHeaderIsNamedNotReadAsPlainEvents) {
  const std::string good = path("good.csv").string();
  ASSERT_EQ(run("process '" + kRpgText + "' -o '" + good + "' -q").exit_code, 0);
  std::string text = evlife::test::read_text_file(good);
  const std::string header = "x,y,t,p,lifetime,vx,vy,prediction_error";
  ASSERT_EQ(text.rfind(header, 0), 0U);
  text.replace(0, header.size(), "x,y,t,p,lifetimf,vx,vy,prediction_error");
  const std::string bad = path("bad.csv").string();
  std::ofstream(bad, std::ios::binary) << text;
  for (const std::string& command : {"info '" + bad + "'", "convert '" + bad + "' '" + path("b.h5").string() + "'",
                                    "eval '" + bad + "' -o '" + path("b_eval").string() + "'"}) {
    const RunResult r = run(command);
    EXPECT_EQ(r.exit_code, 3) << command << "\n" << r.output;
    EXPECT_NE(r.output.find(bad + ": evlife's augmented CSV with a damaged header: 'x,y,t,p,lifetimf,"),
              std::string::npos)
        << command << "\n" << r.output;
  }
  // CSVs of other tools with more columns than x, y, t, p are still plain events, evlife's names among
  // them too (a review helper's finding on a first version, which refused the second).
  for (const auto& [names, rows] : {std::pair{"x,y,t,p,vx,vy", "1,2,10,1,0.5,0.5\n3,4,20,0,0.5,0.5\n"},
                                    std::pair{"x,y,t,p,lifetime,vx,vy,confidence",
                                              "1,2,10,1,0.5,0.5,0.5,0.5\n3,4,20,0,0.5,0.5,0.5,0.5\n"}}) {
    const std::string other = path("other.csv").string();
    std::ofstream(other) << names << "\n" << rows;
    EXPECT_EQ(run("convert '" + other + "' '" + path("o.h5").string() + "' -q").exit_code, 0) << names;
  }
}

// An output naming the input (itself, or through a link) would truncate it
// before the reader reaches its end: every command that reads a file and
// writes events refuses it (exit 2) and leaves the input as it was.
TEST_F(CliTest, NoCommandWritesOverItsInput) {
  ASSERT_EQ(run("process '" + kRpgText + "' -q -o '" + path("in.csv").string() + "'").exit_code, 0);
  const std::string in = path("in.csv").string();
  const std::string before = evlife::test::read_text_file(in);
  ASSERT_GT(before.size(), 1000u);
  fs::create_symlink(in, path("link.csv"));
  // Through a folder the output's path creates (equivalent() failed there: the input became a header).
  for (const std::string& out : {in, path("link.csv").string(), path("new").string() + "/../in.csv"}) {
    for (const std::string& command : {"process " + in + " -o " + out, "run " + in + " -o " + out,
                                       "run --source file:" + in + " -o " + out, "convert " + in + " " + out,
                                       "render " + in + " -o " + out + " --at 0.01"}) {
      const RunResult r = run(command + " -q");
      EXPECT_EQ(r.exit_code, 2) << command << ": " << r.output;
      EXPECT_NE(r.output.find("is the input file"), std::string::npos) << command << ": " << r.output;
      EXPECT_TRUE(evlife::test::read_text_file(in) == before) << command << " changed its input";
    }
  }
  // eval's report folder holding the recording under a name of its report: refused before any work,
  // nothing written (its runs.csv was written over the recording, exit 0).
  fs::create_directories(path("evo"));
  fs::copy_file(in, path("evo/runs.csv"));
  const RunResult report = run("eval " + path("evo/runs.csv").string() + " -q -o " + path("evo").string());
  EXPECT_EQ(report.exit_code, 2) << report.output;
  EXPECT_NE(report.output.find("runs.csv is the input file"), std::string::npos) << report.output;
  EXPECT_TRUE(evlife::test::read_text_file(path("evo/runs.csv")) == before);
  EXPECT_EQ(std::distance(fs::directory_iterator(path("evo")), fs::directory_iterator()), 1);
  // A recording named like a frame, or a video's name linked to it: render read it, then drew over it.
  const std::string png = path("recording.png").string();
  fs::copy_file(kRpgText, png);
  fs::create_symlink(png, path("video.avi"));
  for (const std::string& out : {png, path("video.avi").string()}) {
    const RunResult r = run("render " + png + " -q -o " + out + (out == png ? " --at 0.01" : " --fps 10"));
    EXPECT_EQ(r.exit_code, 2) << out << ": " << r.output;
    EXPECT_NE(r.output.find("is the input file"), std::string::npos) << out << ": " << r.output;
    EXPECT_EQ(fs::file_size(png), fs::file_size(kRpgText)) << out;
  }
}

TEST_F(CliTest, SetOverridesTakeEffect) {
  const RunResult printed = run("process --print-config --set estimator.window_size=7");
  EXPECT_EQ(printed.exit_code, 0) << printed.output;
  EXPECT_NE(printed.output.find("window_size: 7"), std::string::npos) << printed.output;

  // Every plausible lifetime exceeds 1 µs, so with this cap all are noise:
  // every row has lifetime 0 and velocity 0 — while the defaults give some edges.
  const fs::path capped = path("capped.csv");
  const std::string input = path("head.txt").string();
  std::ofstream(input) << rpg_lines(20000);
  ASSERT_EQ(run("process '" + input + "' -o '" + capped.string() +
                "' --set estimator.max_lifetime_us=1")
                .exit_code,
            0);
  std::size_t edges = 0;
  for (const auto& row : csv_rows(capped)) edges += split(row, ',').at(4) != "0";
  EXPECT_EQ(edges, 0u);

  const fs::path defaults = path("defaults.csv");
  ASSERT_EQ(run("process '" + input + "' -o '" + defaults.string() + "'").exit_code, 0);
  edges = 0;
  for (const auto& row : csv_rows(defaults)) edges += split(row, ',').at(4) != "0";
  EXPECT_GT(edges, 0u);
}

TEST_F(CliTest, SameInputSameOutput) {
  const std::string input = path("head.txt").string();
  std::ofstream(input) << rpg_lines(10000);
  ASSERT_EQ(run("process '" + input + "' -o '" + path("a.bin").string() + "' -q").exit_code, 0);
  ASSERT_EQ(run("process '" + input + "' -o '" + path("b.bin").string() + "' -q").exit_code, 0);
  EXPECT_EQ(read_file(path("a.bin")), read_file(path("b.bin")));
}

}  // namespace

namespace {

// A run that stops before it starts leaves a file of the output's name as it
// was: the refused real-time setting (a CPU this machine does not have) is
// found before the output is opened, which empties it.
TEST_F(CliTest, ARefusedRunLeavesAnExistingOutputAsItWas) {
  const std::string out = path("keep.bin").string();
  ASSERT_EQ(run("process '" + kRpgText + "' -q -o " + out).exit_code, 0);
  const std::string before = evlife::test::read_text_file(out);
  ASSERT_GT(before.size(), 1000u);
  const RunResult refused = run("run '" + kRpgText + "' -q --cpus 1000 -o " + out);
  EXPECT_EQ(refused.exit_code, 5) << refused.output;
  EXPECT_NE(refused.output.find("real-time setting refused, nothing processed: --cpus"), std::string::npos)
      << refused.output;
  EXPECT_TRUE(evlife::test::read_text_file(out) == before);
  // A video that is no video is a usage error before the run (it failed at its end, exit 4).
  const RunResult mkv = run("run '" + kRpgText + "' -q --fps 10 --video " + path("v.mkv").string());
  EXPECT_EQ(mkv.exit_code, 2) << mkv.output;
  EXPECT_FALSE(fs::exists(path("v.mkv")));
  // Frames that cannot be written are found before -o is opened (it was emptied to its header before).
  std::ofstream(path("a_file")) << "not a folder";
  const RunResult frames = run("run '" + kRpgText + "' -q --fps 10 --frames " + path("a_file").string() + " -o " + out);
  EXPECT_EQ(frames.exit_code, 4) << frames.output;
  EXPECT_NE(frames.output.find(out + " left as it was"), std::string::npos) << frames.output;
  const RunResult video = run("run '" + kRpgText + "' -q --fps 10 --video /proc/no_such/x.avi -o " + out);
  EXPECT_EQ(video.exit_code, 4) << video.output;
  EXPECT_TRUE(evlife::test::read_text_file(out) == before);
  // A view mode no frame has, and tiles the sensor cannot hold, are refused before -o is opened
  // (both emptied it to its 32-byte header, then exited 2); an empty -o or --frames is refused, as
  // process refuses it (the run went on with its output discarded, exit 0).
  for (const std::string& flags : {"--fps 10 --frames " + path("f").string() + " --mode bogus -o " + out,
                                  "--tiles 300x1 -o " + out, std::string("-o ''"), "--frames '' -o " + out}) {
    const RunResult r = run("run '" + kRpgText + "' -q " + flags);
    EXPECT_EQ(r.exit_code, 2) << flags << ": " << r.output;
    EXPECT_TRUE(evlife::test::read_text_file(out) == before) << flags;
  }
  // A video whose frames its encoder cannot take (MPEG-4: 8191 px a side; compare mode of a 3000 px
  // sensor) is refused before the run, -o as it was (it failed after the whole run, exit 4).
  const std::string wide = path("wide.csv").string();
  std::ofstream(wide) << "x,y,t,p\n0,0,1000,1\n2999,1,2000,0\n";
  const RunResult large = run("run '" + wide + "' --sensor 3000x2 --mode compare --fps 100 -q --video " +
                              path("w.mp4").string() + " -o " + out);
  EXPECT_EQ(large.exit_code, 4) << large.output;
  EXPECT_NE(large.output.find("exceed MPEG-4's 8191 px a side"), std::string::npos) << large.output;
  EXPECT_NE(large.output.find(out + " left as it was"), std::string::npos) << large.output;
  EXPECT_TRUE(evlife::test::read_text_file(out) == before);
  // A file stating a sensor no estimator takes is an input error, as `process` says it (run: exit 2).
  const std::string huge = path("huge.raw").string();
  {
    std::ofstream raw(huge, std::ios::binary);
    raw << "% evt 2.0\n% format EVT2;height=10;width=5000\n% end\n";
    for (const std::uint32_t w : {0x80000001u, 0x10000000u | (5u << 11) | 3u}) raw.write(reinterpret_cast<const char*>(&w), 4);
  }
  for (const char* command : {"process", "run"}) {
    const RunResult r = run(std::string(command) + " '" + huge + "' -q -o " + out);
    EXPECT_EQ(r.exit_code, 3) << command << ": " << r.output;
    EXPECT_NE(r.output.find("sensor 5000x10"), std::string::npos) << command << ": " << r.output;
    EXPECT_NE(r.output.find("is not usable"), std::string::npos) << command << ": " << r.output;
  }
  EXPECT_TRUE(evlife::test::read_text_file(out) == before);
}

// An input that fails while the output fails too: the output's error decides
// (what was written is less than what was processed), and the input's is
// named with it. Before: exit 3, "the events before it were processed and
// written", the output error never said.
TEST_F(CliTest, ARunWhoseInputAndOutputBothFailNamesTheOutputError) {
  const std::string cut = path("cut.aedat").string();
  {
    std::string bytes = evlife::test::read_text_file(kAedat2);
    ASSERT_GT(bytes.size(), 100'005u);
    bytes.resize(100'005);
    std::ofstream(cut, std::ios::binary) << bytes;
  }
  const auto r = run_on_a_small_disk(dir_.path(), "dd if=/dev/zero of=\"$DISK/fill\" bs=1k count=200 2>/dev/null\n'" +
                                                      kCli + "' run '" + cut + "' -q -o \"$DISK/o.bin\"\n"
                                                      "echo \"run exit $?\"\n");
  if (!r) GTEST_SKIP() << "no private tmpfs mount here";
  EXPECT_NE(r->output.find("run exit 4"), std::string::npos) << r->output;
  EXPECT_NE(r->output.find("o.bin"), std::string::npos) << r->output;
  EXPECT_NE(r->output.find("the input had failed as well: " + cut), std::string::npos) << r->output;
}

}  // namespace
