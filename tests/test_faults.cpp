// Fault injection through the `evlife` binary, as a user meets the faults:
// a full disk (/dev/full), an unwritable output path, SIGINT / SIGTERM / SIGHUP in the
// middle of `evlife process` and `evlife run`, bad configuration, absurd
// sizes. Expected behaviour (README, issue "Hardening"): a clear message
// naming the file / key, a non-zero exit, never a crash, and everything
// processed before the fault present in the output, whole rows only.
//
// Inputs are synthetic AEDAT 2.0 files written here with a known content, so
// the output rows are checked against what was written, not against evlife.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "evlife/algo/lifetime_estimator.h"
#include "scratch_dir.h"

extern char** environ;

namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using evlife::test::ScratchDir;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// ---- running the CLI ----
struct Child {
  pid_t pid = -1;
  fs::path out_log;
  fs::path err_log;
};

// `stdout_fd` >= 0: the child's standard output (else a log file).
Child spawn_cli(const std::vector<std::string>& args, const ScratchDir& dir, const std::string& tag,
                int stdout_fd = -1) {
  Child c;
  c.out_log = dir.path() / (tag + ".stdout");
  c.err_log = dir.path() / (tag + ".stderr");
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  if (stdout_fd >= 0) {
    posix_spawn_file_actions_adddup2(&fa, stdout_fd, 1);
  } else {
    posix_spawn_file_actions_addopen(&fa, 1, c.out_log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  }
  posix_spawn_file_actions_addopen(&fa, 2, c.err_log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  std::vector<std::string> all{EVLIFE_CLI_PATH};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  argv.reserve(all.size() + 1);
  for (auto& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  const int rc = posix_spawn(&c.pid, EVLIFE_CLI_PATH, &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) throw std::runtime_error("posix_spawn failed");
  return c;
}

struct Finished {
  bool exited = false;   // false: killed by a signal (a crash)
  int code = -1;         // exit status when exited, else the signal
  std::string out;
  std::string err;
};

// What ended `c` (its wait status) and what it wrote.
Finished finished(const Child& c, int status) {
  Finished f;
  f.exited = WIFEXITED(status);
  f.code = f.exited ? WEXITSTATUS(status) : WTERMSIG(status);
  f.out = slurp(c.out_log);
  f.err = slurp(c.err_log);
  return f;
}

Finished wait_cli(const Child& c) {
  int status = 0;
  while (waitpid(c.pid, &status, 0) < 0) {
    if (errno != EINTR) throw std::runtime_error("waitpid failed");
  }
  return finished(c, status);
}

Finished run_cli(const std::vector<std::string>& args, const ScratchDir& dir) {
  return wait_cli(spawn_cli(args, dir, "cli"));
}

std::string describe(const Finished& f) {
  return std::string(f.exited ? "exit " : "killed by signal ") + std::to_string(f.code) +
         "\n--- stdout ---\n" + f.out + "\n--- stderr ---\n" + f.err;
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

// ---- synthetic input: a DVS128 AEDAT 2.0 file with a known content ----
struct TestEvent {
  std::int64_t t_us;
  int x;
  int y;
  int p;
};

// A vertical ON edge sweeping right (500 us per column), then an OFF edge,
// row by row: the estimator sees real structure. t starts at 1000 us.
TestEvent synthetic_event(std::int64_t i) {
  const std::int64_t step = i / 128;  // one column crossing per step
  const int row = static_cast<int>(i % 128);
  const int x = static_cast<int>(step % 128);
  const int p = (step / 128) % 2 == 0 ? 1 : -1;
  return {1000 + step * 500 + row * 3, x, row, p};
}

void put_be32(std::ofstream& out, std::uint32_t v) {
  const char b[4] = {static_cast<char>(v >> 24), static_cast<char>(v >> 16),
                     static_cast<char>(v >> 8), static_cast<char>(v)};
  out.write(b, 4);
}

// jAER DVS128 layout (see io/formats/src/aedat2_reader.cpp): bit 0 polarity (0 = ON),
// bits 1-7 raw x, bits 8-14 raw y, with x = 127 - raw x, y = 127 - raw y.
void write_aedat2(const fs::path& path, std::int64_t events) {
  std::ofstream out(path, std::ios::binary);
  out << "#!AER-DAT2.0\r\n# AEChip: ch.unizh.ini.jaer.chip.retina.DVS128\r\n";
  for (std::int64_t i = 0; i < events; ++i) {
    const TestEvent e = synthetic_event(i);
    const auto raw_x = static_cast<std::uint32_t>(127 - e.x);
    const auto raw_y = static_cast<std::uint32_t>(127 - e.y);
    put_be32(out, (raw_y << 8) | (raw_x << 1) | (e.p > 0 ? 0u : 1u));
    put_be32(out, static_cast<std::uint32_t>(e.t_us));
  }
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

// Checks the CSV output: the documented header, then whole rows only, each
// carrying the input event of the same index unchanged. Returns the row count.
std::int64_t check_csv_prefix(const fs::path& path, std::int64_t max_rows) {
  const std::string text = slurp(path);
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "x,y,t,p,lifetime,vx,vy,prediction_error");
  EXPECT_TRUE(text.empty() || text.back() == '\n') << "the output ends in a partial row";
  std::int64_t rows = 0;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream ls(line);
    for (std::string field; std::getline(ls, field, ',');) f.push_back(field);
    if (!line.empty() && line.back() == ',') f.emplace_back();  // empty prediction_error
    if (f.size() != 8) {
      ADD_FAILURE() << "row " << rows << " has " << f.size() << " fields: '" << line << "'";
      return rows;
    }
    const TestEvent e = synthetic_event(rows);
    if (std::stoi(f[0]) != e.x || std::stoi(f[1]) != e.y || std::stoll(f[2]) != e.t_us ||
        std::stoi(f[3]) != e.p) {
      ADD_FAILURE() << "row " << rows << " is not input event " << rows << ": '" << line << "'";
      return rows;
    }
    ++rows;
  }
  EXPECT_LE(rows, max_rows);
  return rows;
}

// Starts a long run, waits until the output holds some rows (the run is in
// full swing), sends `sig`, and checks the stop: exit 130 (documented), a
// summary, a message, and an output that is a valid prefix of the input.
void interrupt_mid_run(const std::vector<std::string>& command, int sig, const std::string& tag) {
  const ScratchDir dir("test_faults");
  constexpr std::int64_t kEvents = 3'000'000;  // seconds of work, even in a Release build
  const fs::path input = dir.path() / "long.aedat";
  const fs::path output = dir.path() / "out.csv";
  write_aedat2(input, kEvents);
  std::vector<std::string> args = command;
  for (auto& a : args) {
    if (a == "INPUT") a = input.string();
    if (a == "file:INPUT") a = "file:" + input.string();
    if (a == "OUTPUT") a = output.string();
  }
  const Child c = spawn_cli(args, dir, tag);
  const auto deadline = std::chrono::steady_clock::now() + 120s;
  std::error_code ec;
  while (std::chrono::steady_clock::now() < deadline) {
    if (fs::exists(output, ec) && fs::file_size(output, ec) > 512 * 1024) break;
    int status = 0;
    if (waitpid(c.pid, &status, WNOHANG) == c.pid) {
      FAIL() << tag << ": ended before it could be interrupted (status " << status << ")";
    }
    std::this_thread::sleep_for(2ms);
  }
  ASSERT_EQ(kill(c.pid, sig), 0);
  const Finished f = wait_cli(c);
  ASSERT_TRUE(f.exited) << tag << ": " << describe(f);
  EXPECT_EQ(f.code, 130) << tag << ": " << describe(f);
  EXPECT_TRUE(contains(f.out + f.err, "interrupted")) << tag << ": " << describe(f);
  const std::int64_t rows = check_csv_prefix(output, kEvents);
  EXPECT_GT(rows, 0) << tag;
  EXPECT_LT(rows, kEvents) << tag << ": the signal arrived too late to test anything";
  // The summary states how many events were written: the row count.
  EXPECT_TRUE(contains(f.out + f.err, std::to_string(rows)))
      << tag << ": summary does not state the " << rows << " rows written\n" << describe(f);
}

// ---- output faults ----

TEST(Faults, ProcessToFullDiskFailsClearlyAndNonZero) {
  const ScratchDir dir("test_faults");
  write_aedat2(dir.path() / "in.aedat", 200'000);  // several MB of CSV: more than any buffer
  for (const std::string ext : {".csv", ".bin"}) {
    const fs::path out = dir.path() / ("full" + ext);
    fs::create_symlink("/dev/full", out);
    const Finished f = run_cli({"process", (dir.path() / "in.aedat").string(), "-o", out.string()}, dir);
    ASSERT_TRUE(f.exited) << describe(f);
    EXPECT_NE(f.code, 0) << describe(f);
    EXPECT_TRUE(contains(f.err, out.string())) << "error does not name the output\n" << describe(f);
    EXPECT_TRUE(contains(f.err, "No space left on device")) << describe(f);
  }
}

TEST(Faults, RunToFullDiskFailsClearlyAndNonZero) {
  const ScratchDir dir("test_faults");
  write_aedat2(dir.path() / "in.aedat", 200'000);
  const fs::path out = dir.path() / "full.csv";
  fs::create_symlink("/dev/full", out);
  const Finished f = run_cli(
      {"run", "--source", "file:" + (dir.path() / "in.aedat").string(), "-o", out.string(), "-q"}, dir);
  ASSERT_TRUE(f.exited) << describe(f);
  EXPECT_NE(f.code, 0) << describe(f);
  EXPECT_TRUE(contains(f.err, out.string())) << describe(f);
  EXPECT_TRUE(contains(f.err, "No space left on device")) << describe(f);
}

// synth writes two files batch by batch: a full disk under the ground truth
// fails after the batch went to -o, so each file's count is its own (the one
// count said "0 events handed to the writer" of a -o holding the scene).
TEST(Faults, SynthToAFullDiskNamesTheFileAndWhatEachOutputGot) {
  const ScratchDir dir("test_faults");
  const fs::path events = dir.path() / "scene.txt", truth = dir.path() / "truth.csv";
  fs::create_symlink("/dev/full", truth);
  const Finished f = run_cli({"synth", "-o", events.string(), "--truth", truth.string(), "--duration", "0.01"}, dir);
  ASSERT_TRUE(f.exited) << describe(f);
  EXPECT_EQ(f.code, 4) << describe(f);
  EXPECT_TRUE(contains(f.err, truth.string() + ": write failed: No space left on device")) << describe(f);
  std::ifstream in(events);
  std::size_t lines = 0;
  for (std::string line; std::getline(in, line);) ++lines;
  ASSERT_GT(lines, 0u);
  EXPECT_TRUE(contains(f.err, "(" + std::to_string(lines) + " events handed to the writer of " + events.string() +
                                  ", 0 rows to that of " + truth.string() + " before it)"))
      << lines << " events in " << events << "\n" << describe(f);
}

// A file size limit (ulimit -f, RLIMIT_FSIZE): the write that passes it is an
// output error, exit 4, the file cut back to its last whole record and the
// error saying how many it holds (before, SIGXFSZ killed the process: exit
// 153, no message, a text file ending inside a line, a PNG cut; a review's
// finding). The limit is the child's alone: set around its spawn.
TEST(Faults, AFileSizeLimitIsAnOutputErrorNotASignal) {
  const ScratchDir dir("test_faults");
  write_aedat2(dir.path() / "in.aedat", 20'000);
  const std::string in = (dir.path() / "in.aedat").string();
  rlimit before{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &before), 0);
  if (before.rlim_max != RLIM_INFINITY && before.rlim_max < 100'000) GTEST_SKIP() << "a lower hard limit";
  struct Case {
    std::vector<std::string> args;
    fs::path output;
    std::size_t header_lines;  // lines of the output that are no record; SIZE_MAX: a folder of frames
    rlim_t limit_bytes;        // a file's: inside a line, inside the first frame
  };
  const std::vector<Case> cases = {
      {{"convert", in, (dir.path() / "out.txt").string()}, dir.path() / "out.txt", 0, 60'007},
      {{"process", in, "-o", (dir.path() / "out.csv").string(), "-q"}, dir.path() / "out.csv", 1, 60'007},
      {{"render", in, "-o", (dir.path() / "frames").string(), "--fps", "200", "-q"}, dir.path() / "frames", SIZE_MAX,
       1'003},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args[0]);
    rlimit limited = before;
    limited.rlim_cur = c.limit_bytes;
    ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limited), 0);
    const Child child = spawn_cli(c.args, dir, c.args[0]);
    ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &before), 0);
    const Finished f = wait_cli(child);
    ASSERT_TRUE(f.exited) << describe(f);
    EXPECT_EQ(f.code, 4) << describe(f);
    EXPECT_TRUE(contains(f.err, "File too large")) << describe(f);
    if (c.header_lines == SIZE_MAX) {  // no frame left cut at the limit
      for (const auto& entry : fs::directory_iterator(c.output))
        EXPECT_LT(fs::file_size(entry.path()), c.limit_bytes) << entry.path();
      EXPECT_TRUE(contains(f.err, "(the cut file removed)")) << describe(f);
      continue;
    }
    const std::string text = slurp(c.output);
    ASSERT_FALSE(text.empty()) << describe(f);
    EXPECT_EQ(text.back(), '\n') << describe(f);
    const auto lines = static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
    EXPECT_TRUE(contains(f.err, "the file ends after its last whole record: " + std::to_string(lines - c.header_lines) +
                                    " records in it"))
        << lines << " lines\n" << describe(f);
  }
  // HDF5 keeps room to close its file under the limit, as on a nearly full disk: a file that
  // opens, with the events before the chunk it refused (it was cut and no longer opened).
  write_aedat2(dir.path() / "long.aedat", 100'000);
  const fs::path h5 = dir.path() / "out.h5";
  rlimit limited = before;
  limited.rlim_cur = 2'500'000;  // below a chunk and the room to close: the first chunk is refused
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limited), 0);
  const Child child = spawn_cli({"convert", (dir.path() / "long.aedat").string(), h5.string()}, dir, "h5");
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &before), 0);
  const Finished f = wait_cli(child);
  ASSERT_TRUE(f.exited) << describe(f);
  EXPECT_EQ(f.code, 4) << describe(f);
  EXPECT_TRUE(contains(f.err, "the file size limit (ulimit -f) is near")) << describe(f);
  const Finished info = run_cli({"info", h5.string()}, dir);
  EXPECT_EQ(info.code, 0) << describe(info);
}

// `run` into an .h5 that reaches a file size limit after its first chunk:
// the file opens with that chunk's events, and the summary counts every
// other event as not written. Before, it counted only the batch at hand (the
// events the writer held were counted written), and where the limit came
// within what libhdf5 still held in its caches, the file could not be closed
// and opened nowhere while the summary said "ok".
TEST(Faults, AnHdf5OutputCutByALimitCountsWhatItHolds) {
  const ScratchDir dir("test_faults");
  {  // events at random pixels: they compress as little as real ones
    std::ofstream text(dir.path() / "in.txt");
    text << "128 128\n";
    std::uint32_t state = 12345;
    for (int i = 0; i < 300'000; ++i) {
      state = state * 1664525u + 1013904223u;
      text << (i * 4) / 1e6 << ' ' << (state >> 8) % 128 << ' ' << (state >> 16) % 128 << ' ' << (state >> 31) << '\n';
    }
  }
  rlimit before{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &before), 0);
  if (before.rlim_max != RLIM_INFINITY && before.rlim_max < 5'000'000) GTEST_SKIP() << "a lower hard limit";
  for (const rlim_t limit_bytes : {4'096'000, 4'400'000, 4'600'000}) {
    SCOPED_TRACE(limit_bytes);
    const fs::path h5 = dir.path() / "out.h5";
    fs::remove(h5);
    rlimit limited = before;
    limited.rlim_cur = limit_bytes;
    ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limited), 0);
    const Child child = spawn_cli({"run", (dir.path() / "in.txt").string(), "-o", h5.string()}, dir, "h5run");
    ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &before), 0);
    const Finished f = wait_cli(child);
    ASSERT_TRUE(f.exited) << describe(f);
    EXPECT_EQ(f.code, 4) << describe(f);
    const Finished info = run_cli({"info", h5.string()}, dir);
    ASSERT_EQ(info.code, 0) << describe(info);
    const std::size_t at = info.out.find("events ");
    ASSERT_NE(at, std::string::npos) << info.out;
    std::string digits;
    for (std::size_t i = at + 7; i < info.out.size() && info.out[i] != '('; ++i)
      if (std::isdigit(static_cast<unsigned char>(info.out[i]))) digits += info.out[i];
    const unsigned long long held = std::stoull(digits);
    const std::size_t in_at = f.out.find("balance: in ");
    ASSERT_NE(in_at, std::string::npos) << describe(f);
    const unsigned long long in = std::stoull(f.out.substr(in_at + 12));
    EXPECT_TRUE(contains(f.out, "but " + std::to_string(in - held) + " of the out were not written"))
        << held << " events in the file\n" << describe(f);
  }
}

// A reader that leaves the pipe it reads from: the output behind -o (a FIFO)
// or the standard output. The next write fails (EPIPE): an output error, exit
// 4, that names the output behind -o (before, SIGPIPE killed the process:
// exit 141, no message, no summary).
TEST(Faults, AReaderLeavingThePipeIsAnOutputError) {
  const ScratchDir dir("test_faults");
  write_aedat2(dir.path() / "in.aedat", 200'000);  // several MB: more than the pipe holds
  const std::string in = (dir.path() / "in.aedat").string();
  for (const std::string cmd : {"process", "run"}) {
    const fs::path fifo = dir.path() / (cmd + ".bin");
    ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
    const Child c = spawn_cli({cmd, in, "-o", fifo.string()}, dir, cmd);
    {
      std::ifstream reader(fifo, std::ios::binary);  // meets the writer's open
      std::vector<char> head(1000);
      reader.read(head.data(), static_cast<std::streamsize>(head.size()));
      ASSERT_EQ(reader.gcount(), 1000);
    }  // and leaves
    const Finished f = wait_cli(c);
    ASSERT_TRUE(f.exited) << cmd << ": " << describe(f);
    EXPECT_EQ(f.code, 4) << cmd << ": " << describe(f);
    EXPECT_TRUE(contains(f.err, fifo.string())) << cmd << ": " << describe(f);
    EXPECT_TRUE(contains(f.err, "Broken pipe")) << cmd << ": " << describe(f);
  }
  // Short help (written at the exit's flush) and long help (written while printing).
  for (const std::vector<std::string>& args : {std::vector<std::string>{"--help"},
                                               std::vector<std::string>{"convert", "--help"}}) {
    int ends[2];
    ASSERT_EQ(pipe(ends), 0);
    close(ends[0]);  // nobody reads
    const Child c = spawn_cli(args, dir, "help", ends[1]);
    close(ends[1]);
    const Finished f = wait_cli(c);
    ASSERT_TRUE(f.exited) << args.front() << ": " << describe(f);
    EXPECT_EQ(f.code, 4) << args.front() << ": " << describe(f);
    EXPECT_EQ(f.err, "") << args.front() << ": a reader that left on purpose (`| head`) needs no message\n" << describe(f);
  }
}

// libhdf5 1.10 cannot terminate after a failed create: its exit handler
// printed "HDF5: infinite loop closing library" and a line of FL,FL,... after
// the command's own error.
TEST(Faults, AnHdf5FileThatCannotBeCreatedLeavesNoLibraryNoise) {
  const ScratchDir dir("test_faults");
  write_aedat2(dir.path() / "in.aedat", 1000);
  const fs::path out = dir.path() / "full.h5";
  fs::create_symlink("/dev/full", out);
  const std::string in = (dir.path() / "in.aedat").string();
  for (const auto& args : {std::vector<std::string>{"convert", in, out.string()},
                           std::vector<std::string>{"process", in, "-o", out.string()}}) {
    const Finished f = run_cli(args, dir);
    ASSERT_TRUE(f.exited) << describe(f);
    EXPECT_EQ(f.code, 4) << describe(f);
    // (A device is refused before libhdf5 is asked: it seeks within its file.)
    EXPECT_TRUE(contains(f.err, out.string() + ": not a regular file")) << describe(f);
    EXPECT_FALSE(contains(f.err, "infinite loop")) << describe(f);
  }
}

TEST(Faults, UnwritableOutputPathFailsClearlyAndNonZero) {
  const ScratchDir dir("test_faults");
  write_aedat2(dir.path() / "in.aedat", 1000);
  std::ofstream(dir.path() / "a_file") << "x";  // a regular file used as a directory: ENOTDIR, even for root
  // Missing folders are created (next test), so the second path fails at
  // that creation: a folder cannot be made inside a file either.
  const std::vector<std::string> outputs{(dir.path() / "a_file" / "out.csv").string(),
                                         (dir.path() / "a_file" / "no_such_dir" / "out.h5").string()};
  for (const auto& out : outputs) {
    for (const std::string cmd : {"process", "run"}) {
      const std::vector<std::string> args =
          cmd == "process"
              ? std::vector<std::string>{"process", (dir.path() / "in.aedat").string(), "-o", out}
              : std::vector<std::string>{"run", "--source", "file:" + (dir.path() / "in.aedat").string(),
                                         "-o", out, "-q"};
      const Finished f = run_cli(args, dir);
      ASSERT_TRUE(f.exited) << cmd << ": " << describe(f);
      EXPECT_NE(f.code, 0) << cmd << ": " << describe(f);
      EXPECT_TRUE(contains(f.err, out)) << cmd << ": error does not name " << out << "\n" << describe(f);
      // The folder that could not be made, and why: not the open's "No such file or directory".
      if (contains(out, "no_such_dir")) {
        EXPECT_TRUE(contains(f.err, "cannot create the folder " + (dir.path() / "a_file" / "no_such_dir").string() +
                                        ": Not a directory"))
            << cmd << "\n" << describe(f);
      }
    }
  }
}

// Every command that writes a file creates the folders it names (as render
// always did for its frames): before, process/run/convert/synth refused a
// missing folder while render and eval created theirs.
TEST(Faults, EveryOutputCreatesItsMissingFolders) {
  const ScratchDir dir("test_faults");
  const std::string in = (dir.path() / "in.aedat").string();
  write_aedat2(in, 1000);
  const auto out = [&](const std::string& name) { return (dir.path() / "new" / name / "out").string(); };
  const std::vector<std::vector<std::string>> commands{
      {"process", in, "-o", out("p") + ".csv", "-q"},
      {"process", in, "-o", out("pb") + ".bin", "-q"},
      {"process", in, "-o", out("ph") + ".h5", "-q"},
      {"run", "--source", "file:" + in, "-o", out("r") + ".bin", "-q"},
      {"convert", in, "-o", out("c") + ".h5", "-q"},
      {"synth", "-o", out("s") + ".txt", "--duration", "0.05", "--truth", out("st") + ".csv", "-q"},
      {"render", in, "-o", out("f") + ".png", "--at", "0.001"},
  };
  for (const auto& args : commands) {
    const Finished f = run_cli(args, dir);
    ASSERT_TRUE(f.exited) << args.front() << ": " << describe(f);
    EXPECT_EQ(f.code, 0) << args.front() << ": " << describe(f);
  }
  for (const std::string file : {"p/out.csv", "pb/out.bin", "ph/out.h5", "r/out.bin", "c/out.h5", "s/out.txt",
                                 "st/out.csv", "f/out.png"}) {
    EXPECT_GT(fs::file_size(dir.path() / "new" / file), 0u) << file;
  }
}

// ---- signals mid-run ----

TEST(Faults, ProcessSigintLeavesValidPrefixAndSummary) {
  interrupt_mid_run({"process", "INPUT", "-o", "OUTPUT"}, SIGINT, "process SIGINT");
}

TEST(Faults, ProcessSigtermLeavesValidPrefixAndSummary) {
  interrupt_mid_run({"process", "INPUT", "-o", "OUTPUT"}, SIGTERM, "process SIGTERM");
}

TEST(Faults, RunSigintLeavesValidPrefixAndSummary) {
  interrupt_mid_run({"run", "--source", "file:INPUT", "-o", "OUTPUT"}, SIGINT, "run SIGINT");
}

TEST(Faults, RunSigtermLeavesValidPrefixAndSummary) {
  interrupt_mid_run({"run", "--source", "file:INPUT", "-o", "OUTPUT"}, SIGTERM, "run SIGTERM");
}

// True once process `pid` catches signal `sig` (its handler is installed:
// /proc/PID/status, SigCgt), false if it ended or `wait` passed first.
bool catches(pid_t pid, int sig, std::chrono::milliseconds wait) {
  const auto deadline = std::chrono::steady_clock::now() + wait;
  while (std::chrono::steady_clock::now() < deadline) {
    std::istringstream status(slurp("/proc/" + std::to_string(pid) + "/status"));
    for (std::string line; std::getline(status, line);) {
      if (line.rfind("SigCgt:", 0) == 0 && (std::stoull(line.substr(7), nullptr, 16) >> (sig - 1) & 1U) != 0) {
        return true;
      }
    }
    std::this_thread::sleep_for(1ms);
  }
  return false;
}

// convert, info and render (scanning a text file for its sensor size) stop
// on a signal as process does: exit 130, the output closed with the events
// before the stop (they were killed: an .h5 that opens nowhere, a stdin copy
// left in $TMPDIR). The signal comes as soon as the command catches it,
// before it reads much.
TEST(Faults, ConvertInfoAndRenderStopCleanlyOnASignal) {
  const ScratchDir dir("test_faults");
  write_aedat2(dir.path() / "long.aedat", 3'000'000);
  const std::string in = (dir.path() / "long.aedat").string();
  const fs::path txt = dir.path() / "long.txt";
  ASSERT_EQ(run_cli({"convert", in, txt.string(), "-q"}, dir).code, 0);  // a text file states no sensor
  const fs::path h5 = dir.path() / "out.h5";
  const std::vector<std::vector<std::string>> commands = {
      {"convert", in, h5.string()},
      {"info", in},
      {"render", txt.string(), "-o", (dir.path() / "f.png").string(), "--at", "1"}};
  for (const auto& args : commands) {
    const Child c = spawn_cli(args, dir, args.front());
    const bool caught = catches(c.pid, SIGTERM, 10s);  // before it reads (it never did: killed)
    kill(c.pid, SIGTERM);
    const Finished f = wait_cli(c);
    EXPECT_TRUE(caught) << args.front() << ": SIGTERM never caught";
    ASSERT_TRUE(f.exited) << args.front() << ": " << describe(f);
    EXPECT_EQ(f.code, 130) << args.front() << ": " << describe(f);
    EXPECT_TRUE(contains(f.err, args.front() == "render" ? "interrupted while scanning" : "interrupted"))
        << args.front() << ": " << describe(f);
  }
  const Finished info = run_cli({"info", h5.string()}, dir);  // the .h5 closed: it opens
  EXPECT_EQ(info.code, 0) << describe(info);
}

// A closed terminal or ssh session: the same clean stop (it killed the
// process with its output unclosed before).
TEST(Faults, SighupStopsProcessAndRunCleanly) {
  interrupt_mid_run({"process", "INPUT", "-o", "OUTPUT"}, SIGHUP, "process SIGHUP");
  interrupt_mid_run({"run", "--source", "file:INPUT", "-o", "OUTPUT"}, SIGHUP, "run SIGHUP");
}

// Waits up to `limit` for `c` to end; kills it when it does not (a hang).
std::optional<Finished> wait_cli_within(const Child& c, std::chrono::seconds limit) {
  const auto deadline = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < deadline) {
    int status = 0;
    if (waitpid(c.pid, &status, WNOHANG) == c.pid) return finished(c, status);
    std::this_thread::sleep_for(10ms);
  }
  kill(c.pid, SIGKILL);
  wait_cli(c);
  return std::nullopt;
}

// An output FIFO that no reader opens: a stop signal ends the wait for one,
// exit 130 (before, open() blocked for ever, deaf to Ctrl-C and SIGTERM: the
// command could only be killed). A signal caught before the wait ends the
// run the same way (the run starts stopped, then gives up its output).
TEST(Faults, ASignalWhileRunWaitsForItsOutputFifosReaderStopsIt) {
  const ScratchDir dir("test_faults");
  write_aedat2(dir.path() / "in.aedat", 1000);
  for (const std::string command : {"run", "process", "convert"}) {
    const fs::path fifo = dir.path() / (command + (command == "convert" ? ".txt" : ".bin"));
    ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
    const Child c = spawn_cli({command, (dir.path() / "in.aedat").string(), "-o", fifo.string()}, dir, command);
    const bool caught = catches(c.pid, SIGTERM, 30s);
    std::this_thread::sleep_for(300ms);  // most often into the wait
    kill(c.pid, SIGTERM);
    const std::optional<Finished> f = wait_cli_within(c, 60s);
    EXPECT_TRUE(caught) << command << ": SIGTERM never caught";
    ASSERT_TRUE(f.has_value()) << command << ": still waiting for a reader 60 s after SIGTERM";
    ASSERT_TRUE(f->exited) << command << ": " << describe(*f);
    EXPECT_EQ(f->code, 130) << command << ": " << describe(*f);
    EXPECT_TRUE(contains(f->err, "interrupted")) << command << ": " << describe(*f);
    EXPECT_TRUE(contains(f->err, fifo.string())) << command << ": " << describe(*f);
  }
}

// A reader that opens the output FIFO late gets the whole output.
TEST(Faults, AnOutputFifosLateReaderGetsTheWholeOutput) {
  const ScratchDir dir("test_faults");
  write_aedat2(dir.path() / "in.aedat", 1000);
  const fs::path fifo = dir.path() / "out.bin";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const Child c = spawn_cli({"run", (dir.path() / "in.aedat").string(), "-o", fifo.string()}, dir, "fifo");
  std::this_thread::sleep_for(500ms);
  const fs::path copy = dir.path() / "copy.bin";
  std::ofstream(copy, std::ios::binary) << std::ifstream(fifo, std::ios::binary).rdbuf();
  const std::optional<Finished> f = wait_cli_within(c, 60s);
  ASSERT_TRUE(f.has_value()) << "run did not end after its reader took the output";
  EXPECT_EQ(f->code, 0) << describe(*f);
  const Finished info = run_cli({"info", copy.string()}, dir);  // a whole .bin: its header and records
  EXPECT_EQ(info.code, 0) << describe(info);
  EXPECT_TRUE(contains(info.out, "augmented-bin")) << describe(info);
  EXPECT_TRUE(contains(info.out, "1000")) << describe(info);
}

// ---- configuration ----

TEST(Faults, ConfigUnknownKeyIsNamed) {
  const ScratchDir dir("test_faults");
  write_aedat2(dir.path() / "in.aedat", 1000);
  const fs::path cfg = dir.path() / "bad.yaml";
  std::ofstream(cfg) << "estimator:\n  window_size: 5\n  windw_size: 7\n";
  const Finished f = run_cli({"process", (dir.path() / "in.aedat").string(), "-o",
                              (dir.path() / "out.csv").string(), "--config", cfg.string()},
                             dir);
  ASSERT_TRUE(f.exited) << describe(f);
  EXPECT_NE(f.code, 0) << describe(f);
  EXPECT_TRUE(contains(f.err, "windw_size")) << describe(f);
  EXPECT_TRUE(contains(f.err, cfg.string())) << "error does not name the file\n" << describe(f);
}

TEST(Faults, ConfigValueOutOfRangeNamesKeyAndRange) {
  const ScratchDir dir("test_faults");
  write_aedat2(dir.path() / "in.aedat", 1000);
  const fs::path cfg = dir.path() / "bad.yaml";
  std::ofstream(cfg) << "estimator:\n  outlier_fraction: 1.5\n";
  const Finished f = run_cli({"process", (dir.path() / "in.aedat").string(), "-o",
                              (dir.path() / "out.csv").string(), "--config", cfg.string()},
                             dir);
  ASSERT_TRUE(f.exited) << describe(f);
  EXPECT_NE(f.code, 0) << describe(f);
  EXPECT_TRUE(contains(f.err, "outlier_fraction")) << describe(f);
  EXPECT_TRUE(contains(f.err, "0.9")) << "error does not state the allowed range\n" << describe(f);
}

// ---- absurd sizes: refused up front with a message, not an allocation failure ----

TEST(Faults, WindowSize99IsRefusedWithItsRange) {
  const ScratchDir dir("test_faults");
  write_aedat2(dir.path() / "in.aedat", 1000);
  for (const std::string cmd : {"process", "run"}) {
    const std::vector<std::string> args =
        cmd == "process" ? std::vector<std::string>{"process", (dir.path() / "in.aedat").string(), "-o",
                                                    (dir.path() / "out.csv").string(), "--set",
                                                    "estimator.window_size=99"}
                         : std::vector<std::string>{"run", "--source",
                                                    "file:" + (dir.path() / "in.aedat").string(), "--set",
                                                    "estimator.window_size=99"};
    const Finished f = run_cli(args, dir);
    ASSERT_TRUE(f.exited) << cmd << ": " << describe(f);
    EXPECT_NE(f.code, 0) << cmd << ": " << describe(f);
    EXPECT_TRUE(contains(f.err, "window_size")) << cmd << ": " << describe(f);
    EXPECT_TRUE(contains(f.err, "15")) << cmd << ": range not stated\n" << describe(f);
    EXPECT_FALSE(fs::exists(dir.path() / "out.csv")) << cmd << ": output created before validation";
  }
}

TEST(Faults, HugeSensorIsRefusedWithItsRange) {
  const ScratchDir dir("test_faults");
  write_aedat2(dir.path() / "in.aedat", 1000);
  const fs::path txt = dir.path() / "in.txt";  // a format that does not state its sensor
  std::ofstream(txt) << "0.001 1 2 1\n0.002 3 4 0\n";
  for (const std::string cmd : {"process", "run"}) {
    const std::vector<std::string> args =
        cmd == "process" ? std::vector<std::string>{"process", txt.string(), "-o",
                                                    (dir.path() / "out.csv").string(), "--sensor",
                                                    "100000x100000"}
                         : std::vector<std::string>{"run", "--source", "file:" + txt.string(),
                                                    "--sensor", "100000x100000"};
    const Finished f = run_cli(args, dir);
    ASSERT_TRUE(f.exited) << cmd << ": " << describe(f);
    EXPECT_NE(f.code, 0) << cmd << ": " << describe(f);
    EXPECT_TRUE(contains(f.err, "4096")) << cmd << ": range not stated\n" << describe(f);
    EXPECT_FALSE(contains(f.err, "bad_alloc")) << cmd << ": " << describe(f);
  }
}

TEST(Faults, EstimatorRefusesAbsurdOptionsAtConstruction) {
  evlife::LifetimeOptions o;
  o.sensor = {100000, 100000};
  try {
    evlife::LifetimeEstimator est(o);
    ADD_FAILURE() << "a 100000x100000 sensor was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_TRUE(contains(e.what(), "sensor")) << e.what();
  }
  o = evlife::LifetimeOptions{};
  o.window_size = 99;
  try {
    evlife::LifetimeEstimator est(o);
    ADD_FAILURE() << "window_size 99 was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_TRUE(contains(e.what(), "window_size")) << e.what();
  }
}

}  // namespace
