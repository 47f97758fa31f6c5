// `evlife render` and `evlife eval` run as a user would (the built binary):
// frames at chosen instants, videos, exit codes, and the evaluation's numbers
// checked against `evlife process` output decoded here.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "cli_runner.h"
#include "evlife/render/evaluation.h"
#include "sanitizer_build.h"
#include "scratch_dir.h"

namespace {

namespace fs = std::filesystem;

const std::string kCli = EVLIFE_CLI_PATH;
const std::string kData = EVLIFE_SHARED_DATA_DIR;
const std::string kStripes = kData + "/reference/stripes.mat";
const std::string kGarfield = kData + "/reference/garfield.mat";

using RunResult = evlife::test::CliRun;

class RenderCliTest : public testing::Test {
 protected:
  RunResult run(const std::string& args) const { return evlife::test::run_cli(kCli, args, dir_.path() / "cli.log"); }
  std::string path(const std::string& name) const { return dir_.file(name); }
  const evlife::test::ScratchDir dir_{"test_render_cli"};
};

// 2000 events over 0.1 s on a 64x32 sensor, then one at `outlier_us`.
void write_events_then_outlier(const std::string& csv, long long outlier_us) {
  std::ofstream f(csv);
  for (int i = 0; i < 2000; ++i) f << (i % 64) << ',' << (i / 64) % 64 << ",1," << i * 50 << '\n';
  f << "5,5,1," << outlier_us << '\n';
}

TEST_F(RenderCliTest, HelpExplainsTheOptions) {
  const auto r = run("render --help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* word : {"--at", "--fps", "--from", "--to", "compare", "window:", ".mp4", ".avi", "--scale"})
    EXPECT_NE(r.output.find(word), std::string::npos) << word;
  const auto e = run("eval --help");
  EXPECT_EQ(e.exit_code, 0);
  EXPECT_NE(e.output.find("prediction_error_cdf"), std::string::npos);
}

// Image files load the plugin libevlife_media.so on demand; a command that
// draws nothing runs without it (the point: it starts without ~200 codec and
// GUI libraries), and a missing plugin is a clear output error.
TEST_F(RenderCliTest, OnlyCommandsThatDrawLoadTheMediaPlugin) {
  const std::string missing = "EVLIFE_MEDIA_PLUGIN='" + path("none/libevlife_media.so") + "' ";
  auto r = evlife::test::run_cli("/usr/bin/env", missing + "'" + kCli + "' process '" + kGarfield + "' -o '" +
                                                     path("g.bin") + "' -q", dir_.path() / "cli.log");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  r = evlife::test::run_cli("/usr/bin/env", missing + "'" + kCli + "' render '" + kGarfield + "' -o '" +
                                                path("g.png") + "' --at 0.5 -q", dir_.path() / "cli.log");
  EXPECT_EQ(r.exit_code, 4) << r.output;
  EXPECT_NE(r.output.find("cannot load libevlife_media.so"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(path("none/libevlife_media.so")), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(path("g.png")));
}

TEST_F(RenderCliTest, CompareFramesAtChosenInstantsSameFromRawAndFromAugmented) {
  auto r = run("render '" + kStripes + "' -o '" + path("raw") + "' --at 0.5,0.25 --mode compare -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // Sorted, named by time; 3 panels of 128x4 px + gaps + legend; labels + caption.
  const std::string f0 = path("raw") + "/frame_000000_t0.250000s.png";
  const std::string f1 = path("raw") + "/frame_000001_t0.500000s.png";
  const cv::Mat a = cv::imread(f0);
  ASSERT_FALSE(a.empty()) << f0;
  EXPECT_FALSE(cv::imread(f1).empty()) << f1;
  EXPECT_EQ(a.cols, 3 * 512 + 2 * 4 + 4 + 96);
  EXPECT_EQ(a.rows, 22 + 512 + 24);
  // One instant into one named PNG: the same image.
  r = run("render '" + kStripes + "' -o '" + path("one.png") + "' --at 0.25 --mode compare -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(cv::norm(a, cv::imread(path("one.png")), cv::NORM_INF), 0.0);

  // The same instants from the augmented file written by `evlife process`.
  r = run("process '" + kStripes + "' -o '" + path("stripes.bin") + "' -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run("render '" + path("stripes.bin") + "' -o '" + path("aug") + "' --at 0.25,0.5 --mode compare -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const cv::Mat b = cv::imread(path("aug") + "/frame_000000_t0.250000s.png");
  ASSERT_EQ(a.size(), b.size());
  // The caption differs in nothing but both are drawn the same: images equal.
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
}

// `process -o x.h5` reads back as the .bin does: the same frame, the same
// records through convert, and its lifetimes are not estimated again (an
// estimator setting is refused for it, as for the .bin). Before, render took
// the .h5 as events and estimated them again with the options of the moment.
TEST_F(RenderCliTest, AnAugmentedH5IsReadBackAsItsBin) {
  // Not the default options: a file estimated again with the defaults would draw another frame.
  for (const std::string out : {"g.bin", "g.h5"}) {
    const auto r = run("process '" + kGarfield + "' --to 0.3 --set estimator.window_size=7 -o '" + path(out) + "' -q");
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  for (const std::string in : {"g.bin", "g.h5"}) {
    const auto r = run("render '" + path(in) + "' -o '" + path(in + ".png") + "' --at 0.2 --mode compare -q");
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  const cv::Mat from_bin = cv::imread(path("g.bin.png"));
  ASSERT_FALSE(from_bin.empty());
  EXPECT_EQ(cv::norm(from_bin, cv::imread(path("g.h5.png")), cv::NORM_INF), 0.0);
  auto r = run("convert '" + path("g.h5") + "' '" + path("again.bin") + "' -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto bytes_of = [](const std::string& file) {
    std::ifstream in(file, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  ASSERT_GT(bytes_of(path("g.bin")).size(), 1'000'000u);
  EXPECT_TRUE(bytes_of(path("again.bin")) == bytes_of(path("g.bin")));
  r = run("render '" + path("g.h5") + "' -o '" + path("x.png") + "' --at 0.2 --set estimator.window_size=7 -q");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("nothing to estimate in"), std::string::npos) << r.output;
  r = run("info '" + path("g.h5") + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("augmented-hdf5"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("as estimated when the file was written"), std::string::npos) << r.output;
}

// The README's frames are what the estimator draws now: regenerate them
// (the command in the README's caption) when a change moves them. A change
// of the estimator moved 1.3 % (stripes) and 2.3 % (garfield) of their
// pixels; the allowance covers only rounding differences between compilers.
TEST_F(RenderCliTest, ReadmeFramesAreTheCurrentEstimatorsOutput) {
  for (const std::string name : {"stripes", "garfield"}) {
    const std::string input = name == "stripes" ? kStripes : kGarfield;
    const std::string drawn = path(name + ".png");
    const auto r = run("render '" + input + "' -o '" + drawn + "' --at 0.5 --mode compare -q");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const std::string readme_frame = std::string(EVLIFE_SOURCE_DIR) + "/render/doc/" + name + "_compare.png";
    const cv::Mat a = cv::imread(drawn);
    const cv::Mat b = cv::imread(readme_frame);
    ASSERT_FALSE(b.empty()) << readme_frame;
    ASSERT_EQ(a.size(), b.size()) << readme_frame;
    cv::Mat diff;
    cv::absdiff(a, b, diff);
    cv::Mat changed;
    cv::cvtColor(diff, changed, cv::COLOR_BGR2GRAY);
    const double share = cv::countNonZero(changed) / static_cast<double>(changed.total());
    EXPECT_LE(share, 0.001) << readme_frame << " is stale: regenerate it with `evlife render " << input << " -o "
                            << readme_frame << " --at 0.5 --mode compare`";
  }
}

// A video to a FIFO (or a device): refused up front, exit 4. Its writes
// fail unreported (a reader that left), and the check of the finished file,
// read back, waited for ever on the FIFO, deaf to Ctrl-C.
TEST_F(RenderCliTest, AVideoIsWrittenToARegularFileOnly) {
  const std::string fifo = path("pipe.avi");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  for (const std::string& command : {"render '" + kGarfield + "' -o '" + fifo + "' --fps 20 --to 0.3",
                                     "run '" + kGarfield + "' --video '" + fifo + "' --to 0.3 -o '" + path("r.bin") + "'"}) {
    const auto r = evlife::test::run_cli("timeout", "-k 5 60 '" + kCli + "' " + command, dir_.path() / "cli.log");
    EXPECT_EQ(r.exit_code, 4) << command << "\n" << r.output;
    EXPECT_NE(r.output.find(fifo + ": not a regular file (a folder, a pipe or a device)"), std::string::npos)
        << r.output;
  }
}

// A frame wider than its codec's encoder takes is refused by name: JPEG holds
// at most 65500 px a side (OpenCV's own AVI writer wrapped the side at 65536:
// a corrupt video, exit 0), FFmpeg's MPEG-4 encoder 8191 (said to be "a
// missing encoder").
TEST_F(RenderCliTest, AVideoFrameWiderThanItsCodecAllowsIsRefused) {
  const std::string csv = path("wide.csv");
  std::ofstream(csv) << "x,y,t,p\n0,0,1000,1\n2099,1,2000,0\n";
  for (const auto& [name, scale, limit] : {std::tuple{"wide.avi", "32", "67300x126 px exceed JPEG's 65500 px a side"},
                                           std::tuple{"wide.mp4", "4", "8500x126 px exceed MPEG-4's 8191 px a side"}}) {
    const std::string video = path(name);
    const auto r = run("render '" + csv + "' -o '" + video + "' --fps 1000 --scale " + scale + " --sensor 2100x2 -q");
    EXPECT_EQ(r.exit_code, 4) << r.output;
    EXPECT_NE(r.output.find("cannot write the video " + video + ": its frames of " + limit), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(video));
  }
}

// A frame larger than the memory there is is refused before anything is
// drawn or written (and before the estimator's planes, 1.5 GB here, are
// touched: 20 s on a VM), naming its size and the flag to lower: exit 2, where
// OpenCV's allocation failed as "unexpected error", exit 1.
TEST_F(RenderCliTest, AFrameLargerThanTheMemoryIsRefusedUpFront) {
  // 3 x (4096 x 32 + 36) px wide, 4096 x 32 + 46 px high (compare, caption): 154.7 GB.
  const auto available = evlife::test::available_memory_bytes();
  if (!available || *available > 150'000'000'000ULL) GTEST_SKIP() << "this machine has the memory";
  const std::string csv = path("two.csv");
  std::ofstream(csv) << "x,y,t,p\n0,0,1000,1\n1,1,2000,0\n";
  const std::string png = path("huge.png");
  const auto r = run("render '" + csv + "' -o '" + png + "' --at 1ms --mode compare --scale 32 --sensor 4096x4096 -q");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("a frame of 393324x131118 px needs at least 154.7 GB, more than the"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("(sensor 4096x4096 at --scale 32): lower --scale"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(png));
}

TEST_F(RenderCliTest, VideoHasOneFramePerInstant) {
  // 0 .. 0.3 s at 20 fps: instants 0, 0.05, ..., 0.30 = 7 frames.
  for (const char* name : {"v.avi", "v.mp4"}) {
    const auto r = run("render '" + kGarfield + "' -o '" + path(name) + "' --fps 20 --to 0.3 -q");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    cv::VideoCapture cap(path(name));
    ASSERT_TRUE(cap.isOpened()) << name;
    int frames = 0;
    cv::Mat f;
    while (cap.read(f)) {
      EXPECT_EQ(f.cols, 512 + 4 + 96);
      ++frames;
    }
    EXPECT_EQ(frames, 7) << name;
  }
  // No frame to draw (--from after the last event): an earlier video of that
  // name is left as it was (before: replaced by a video of no frame), and no
  // probe file is left beside it.
  const std::string before = evlife::test::read_text_file(path("v.avi"));
  const auto none = run("render '" + kGarfield + "' -o '" + path("v.avi") + "' --fps 20 --from 100 -q");
  EXPECT_EQ(none.exit_code, 3) << none.output;
  EXPECT_NE(none.output.find("nothing written to " + path("v.avi")), std::string::npos) << none.output;
  EXPECT_TRUE(evlife::test::read_text_file(path("v.avi")) == before);
  for (const auto& entry : std::filesystem::directory_iterator(dir_.path()))
    EXPECT_EQ(entry.path().filename().string().rfind(".evlife-probe", 0), std::string::npos) << entry.path();
}

// Videos of frames an encoder cannot take as they are: a few pixels wide (libswscale wrote past
// its buffers: heap corruption, exit 134) or of odd sides (the last column and row were lost).
// The frames are padded black to even sides of at least 16 px; every drawn pixel is in the video.
TEST_F(RenderCliTest, VideoFramesOfAnySizeArePaddedForTheEncoderNotCutOrOverrun) {
  const std::string tiny = path("tiny.csv");
  {
    std::ofstream f(tiny);
    f << "x,y,t,p,lifetime,vx,vy,prediction_error\n0,0,0,1,1000,0,0,\n1,1,1000000,1,1000,0,0,\n";
  }
  const std::string odd = path("odd.csv");
  {
    std::ofstream f(odd);
    f << "x,y,t,p,lifetime,vx,vy,prediction_error\n0,0,0,1,100000,0,0,\n240,180,10,1,100000,0,0,\n"
      << "120,90,100,-1,100000,0,0,\n";
  }
  for (const char* ext : {"avi", "mp4"}) {
    const std::string video = path(std::string("tiny.") + ext);
    const auto r = run("render '" + tiny + "' -o '" + video + "' --fps 1 --no-caption --no-legend --scale 1");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("video size          16x24 px: frames padded"), std::string::npos) << r.output;
    cv::VideoCapture cap(video);
    ASSERT_TRUE(cap.isOpened()) << video;
    int frames = 0;
    cv::Mat f;
    while (cap.read(f)) {
      EXPECT_EQ(f.size(), cv::Size(16, 24)) << video;
      ++frames;
    }
    EXPECT_EQ(frames, 2) << video;

    const std::string odd_video = path(std::string("odd.") + ext);
    const auto o = run("render '" + odd + "' -o '" + odd_video +
                       "' --at 50us --no-caption --no-legend --scale 1 --color plain -q");
    ASSERT_EQ(o.exit_code, 0) << o.output;
    cv::VideoCapture odd_cap(odd_video);
    ASSERT_TRUE(odd_cap.isOpened() && odd_cap.read(f)) << odd_video;
    EXPECT_EQ(f.size(), cv::Size(242, 204)) << odd_video;  // 241x203: the 241x181 sensor under a 22 px title
    cv::Mat grey;
    cv::cvtColor(f, grey, cv::COLOR_BGR2GRAY);
    // The event at the sensor's last column and row (lossy codecs: bright, not exactly white).
    EXPECT_GT(grey.at<std::uint8_t>(202, 240), 100) << odd_video;
    EXPECT_LT(grey.at<std::uint8_t>(203, 241), 60) << odd_video << ": the padding is black";
  }
}

// `render --fps` without --to stops before every gap of kEventGapStopFrames (100,000) empty
// frames or more, not only the first gap it sees, and whatever the gap lasts in seconds.
TEST_F(RenderCliTest, AFrameRateStopsBeforeEveryHugeGapNotOnlyTheFirst) {
  const std::string gaps = path("gaps.csv");
  {
    std::ofstream f(gaps);
    f << "x,y,t,p,lifetime,vx,vy,prediction_error\n0,0,0,1,1000,0,0,\n1,1,1000,1,1000,0,0,\n"
      << "1,0,1100000000,1,1000,0,0,\n0,1,201100000000,1,1000,0,0,\n";
  }
  auto r = run("render '" + gaps + "' --sensor 4x2 -o '" + path("gaps") + "' --fps 1 --no-caption --no-legend --scale 1");
  EXPECT_EQ(r.exit_code, 3) << r.output;  // before: the first gap warned, then 199,999 empty frames were drawn
  EXPECT_NE(r.output.find("1098 empty frames at 1 fps come first"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("199999 empty frames at 1 fps come first; a timestamp outlier? Stopped before them"),
            std::string::npos) << r.output;
  // Frame 1100 at 1100 s shows the event there (before: it was not drawn).
  EXPECT_NE(r.output.find("the 1101 frames before the fault"), std::string::npos) << r.output;
  // 30 s without events at 5000 fps: 150,000 frames, though shorter than the 60 s a warning needs.
  const std::string pause = path("pause.csv");
  {
    std::ofstream f(pause);
    f << "x,y,t,p,lifetime,vx,vy,prediction_error\n0,0,0,1,1000,0,0,\n1,1,30000000,1,1000,0,0,\n";
  }
  r = run("render '" + pause + "' --sensor 4x2 -o '" + path("pause") + "' --fps 5000 --scale 1 -q");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("149999 empty frames at 5000 fps"), std::string::npos) << r.output;
}

// A fixed window is drawn exactly up to its longest (537 s of 32-bit history
// behind the newest event); a longer one is refused (before: window:3600s
// silently left out events older than ~45 min).
TEST_F(RenderCliTest, LongWindowsAreExactOrRefused) {
  std::ofstream(path("gap.txt")) << "0.000000 1 1 1\n500.000000 2 2 1\n";
  auto r = run("render '" + path("gap.txt") + "' -o '" + path("gap_frames") +
               "' --at 500 --mode window:530s --color plain --scale 1 --no-caption --no-legend --sensor 4x4 -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const cv::Mat image = cv::imread(path("gap_frames") + "/frame_000000_t500.000000s.png", cv::IMREAD_GRAYSCALE);
  ASSERT_EQ(image.cols, 4);
  const cv::Mat frame = image.rowRange(image.rows - 4, image.rows);  // under the panel's label
  EXPECT_GT(frame.at<unsigned char>(1, 1), 0) << "the event 500 s before the instant";
  EXPECT_GT(frame.at<unsigned char>(2, 2), 0);
  EXPECT_EQ(cv::countNonZero(frame), 2);
  r = run("render '" + path("gap.txt") + "' -o '" + path("gap_frames") + "' --at 500 --mode window:3600s --sensor 4x4");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("window longer than the longest drawn exactly, 536 s, in 'window:3600s'"), std::string::npos)
      << r.output;
}

TEST_F(RenderCliTest, BadArgumentsAndInputsGiveClearErrors) {
  auto r = run("render '" + path("missing.mat") + "' -o '" + path("out") + "' --at 0.1");
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.output.find("missing.mat"), std::string::npos) << r.output;
  r = run("render '" + kStripes + "' -o '" + path("out") + "' --mode blur");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("blur"), std::string::npos) << r.output;
  r = run("render '" + kStripes + "' -o '" + path("out") + "' --at 0.1 --fps 3");
  EXPECT_EQ(r.exit_code, 2);
  r = run("render '" + kStripes + "' -o '" + path("out.png") + "' --at 0.1,0.2");
  EXPECT_EQ(r.exit_code, 2) << "one PNG cannot hold two instants";
  r = run("render '" + kStripes + "' -o '" + path("out.jpg") + "' --at 0.1");
  EXPECT_EQ(r.exit_code, 2);
  r = run("render '" + kStripes + "' -o '" + path("out") + "' --at 0.1 --set estimator.window_size=4");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  r = run("eval '" + path("missing.mat") + "' -o '" + path("ev") + "'");
  EXPECT_EQ(r.exit_code, 3);
}

// --frames and --video name the output as `evlife run` takes them: --frames a
// folder whatever its name, --video a video only; -o by its extension
// (render took both for -o: --video DIR/ wrote PNGs, --frames x.mp4 a video).
TEST_F(RenderCliTest, FramesAndVideoFlagsNameTheOutputAsRunTakesThem) {
  auto r = run("render '" + kStripes + "' --video '" + path("vdir") + "/' --at 0.1 -q");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("the video must end in .mp4 or .avi (--frames DIR for PNG frames)"), std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(path("vdir")));
  r = run("render '" + kStripes + "' --frames '" + path("fx.mp4") + "' --at 0.1,0.2 -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ASSERT_TRUE(fs::is_directory(path("fx.mp4")));
  EXPECT_EQ(std::distance(fs::directory_iterator(path("fx.mp4")), fs::directory_iterator{}), 2);
  r = run("render '" + kStripes + "' -o '" + path("a") + "' --frames '" + path("b") + "' --at 0.1 -q");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("give one"), std::string::npos) << r.output;
}

// No frame is written over the input: a recording in the frames' folder under
// a frame's name (it was replaced by the PNG, exit 0), also through a link.
TEST_F(RenderCliTest, NoFrameIsWrittenOverTheInput) {
  fs::create_directories(path("fdir"));
  const std::string input = path("fdir") + "/frame_000000_t0.500000s.png";
  fs::copy_file(kStripes, input);
  fs::create_directories(path("ldir"));
  fs::create_hard_link(input, path("ldir") + "/frame_000000_t0.500000s.png");
  for (const std::string& command : {"render '" + input + "' -o '" + path("fdir") + "' --at 0.5",
                                    "render '" + input + "' -o '" + path("ldir") + "' --at 0.5",
                                    "run '" + input + "' --frames '" + path("fdir") + "' --fps 0 --at 0.5"}) {
    SCOPED_TRACE(command);
    const auto r = run(command);
    EXPECT_EQ(r.exit_code, 4) << r.output;
    EXPECT_NE(r.output.find("is the input file; refusing to overwrite it"), std::string::npos) << r.output;
    EXPECT_EQ(fs::file_size(input), fs::file_size(kStripes));
  }
}

// The summary says where noise is drawn: never in the lifetime view, as any
// event in a fixed window (it said "never drawn" in every mode).
TEST_F(RenderCliTest, TheSummarySaysWhereNoiseIsDrawn) {
  for (const auto& [mode, said] : std::vector<std::pair<std::string, std::string>>{
           {"lifetime", "noise (never drawn)"},
           {"window:30ms", "noise (drawn as any event)"},
           {"compare", "noise (drawn in the fixed windows only)"}}) {
    const auto r = run("render '" + kStripes + "' -o '" + path("n_" + mode.substr(0, 3) + ".png") + "' --at 0.5 --mode " + mode);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find(said), std::string::npos) << mode << "\n" << r.output;
  }
}

// A fixed window has no lifetime to colour by: `--color lifetime` (the
// default) of windows alone draws them plain, and the caption and summary say
// so (they said "colour lifetime"); thinning is said to spare the windows.
TEST_F(RenderCliTest, WindowModeSaysItsEventsAreDrawnPlain) {
  const auto as_lifetime = run("render '" + kStripes + "' -o '" + path("wl.png") + "' --at 0.5 --mode window:30ms");
  const auto as_plain = run("render '" + kStripes + "' -o '" + path("wp.png") + "' --at 0.5 --mode window:30ms --color plain");
  ASSERT_EQ(as_lifetime.exit_code, 0) << as_lifetime.output;
  ASSERT_EQ(as_plain.exit_code, 0) << as_plain.output;
  for (const auto* r : {&as_lifetime, &as_plain}) {
    EXPECT_NE(r->output.find("mode window:30ms, colour plain)"), std::string::npos) << r->output;
    EXPECT_NE(r->output.find(" thinned (by the estimator; a fixed window draws them)"), std::string::npos) << r->output;
  }
  const cv::Mat a = cv::imread(path("wl.png"));
  const cv::Mat b = cv::imread(path("wp.png"));
  ASSERT_FALSE(a.empty());
  ASSERT_EQ(a.size, b.size);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0) << "the captions differ";
  const auto lifetime = run("render '" + kStripes + "' -o '" + path("ll.png") + "' --at 0.5");
  EXPECT_NE(lifetime.output.find("mode lifetime, colour lifetime)"), std::string::npos) << lifetime.output;
}

// A text file of eval's that the disk refuses (here /dev/full: its writes fail
// at the flush) is an output error naming it, not an empty file and exit 0.
TEST_F(RenderCliTest, EvalReportsATextFileTheDiskRefused) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  for (const std::string name : {"runs.csv", "summary.html", "sharpness.csv"}) {
    const std::string dir = path("full_" + name);
    fs::create_directories(dir);
    fs::create_symlink("/dev/full", dir + "/" + name);
    const auto r = run("eval '" + kGarfield + "' --to 0.1 -o '" + dir + "' -q");
    EXPECT_EQ(r.exit_code, 4) << name << ": " << r.output;
    EXPECT_NE(r.output.find("cannot write " + dir + "/" + name), std::string::npos) << r.output;
  }
}

// A PNG whose last bytes the disk refuses (here a file size limit one byte
// short of the image, RLIMIT_FSIZE, whose write() stops short as a full
// disk's does): OpenCV's imwrite flushed its last stdio buffer in an
// unchecked fclose, so the cut image passed with exit 0 (render's frames,
// run's, eval's figures alike). Now an output error naming the file and why.
TEST_F(RenderCliTest, AnImageTheDiskCutsAtItsLastBytesIsAnOutputError) {
  const std::string whole = path("whole.png");
  ASSERT_EQ(run("render '" + kGarfield + "' -o '" + whole + "' --at 0.1 -q").exit_code, 0);
  const auto bytes = static_cast<rlim_t>(fs::file_size(whole));
  rlimit before{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &before), 0);
  if (before.rlim_max != RLIM_INFINITY && before.rlim_max < bytes) GTEST_SKIP() << "a lower hard limit";
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);  // write() fails with EFBIG instead
  rlimit limited = before;
  limited.rlim_cur = bytes - 1;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limited), 0);
  const std::string cut = path("cut.png");
  const auto r = run("render '" + kGarfield + "' -o '" + cut + "' --at 0.1 -q");
  setrlimit(RLIMIT_FSIZE, &before);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_EQ(r.exit_code, 4) << r.output;
  EXPECT_NE(r.output.find("cannot write " + cut + ": File too large"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(cut)) << "the cut image is removed, not left to read as one";
}

// A frame larger than an address-space limit (`ulimit -v`) lets the process
// map is refused up front as one larger than the machine's memory is (it
// exited 1 with OpenCV's "Insufficient memory ... OutOfMemoryError").
TEST_F(RenderCliTest, AFrameBeyondTheAddressSpaceLimitIsRefusedUpFront) {
  if (evlife::test::kSanitizerBuild) GTEST_SKIP() << "a sanitizer's shadow memory exceeds any such limit";
  const std::string evt3 = kData + "/evt3/evt3_sample.raw";  // 1280x720: 2.8 GB at --scale 32
  rlimit before{};
  ASSERT_EQ(getrlimit(RLIMIT_AS, &before), 0);
  const rlim_t limit = rlim_t{1500} << 20;
  if (before.rlim_max != RLIM_INFINITY && before.rlim_max < limit) GTEST_SKIP() << "a lower hard limit";
  rlimit limited = before;
  limited.rlim_cur = limit;
  ASSERT_EQ(setrlimit(RLIMIT_AS, &limited), 0);
  const auto r = run("render '" + evt3 + "' --at 0.001 --scale 32 -o '" + path("huge.png") + "'");
  setrlimit(RLIMIT_AS, &before);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("a frame of 41060x23086 px needs at least 2.8 GB, more than the "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(" this process may still map (its address-space limit, ulimit -v)"), std::string::npos) << r.output;
}

// An empty output is a bad command line, as `run -o ''` is; a folder that
// cannot be made says why (before: exit 4 "cannot create directory :
// Invalid argument" from render, "cannot create directory " from eval, and
// eval's reason left out for a path through a file).
TEST_F(RenderCliTest, AnEmptyOrUnmakeableOutputFolderIsNamedWithWhy) {
  for (const std::string& args : {"render '" + kGarfield + "' -o '' --at 0.1", "render '" + kGarfield +
                                  "' --frames '' --at 0.1", "eval '" + kGarfield + "' -o ''"}) {
    const auto r = run(args + " -q");
    EXPECT_EQ(r.exit_code, 2) << args << ": " << r.output;
    EXPECT_NE(r.output.find("is empty"), std::string::npos) << r.output;
  }
  const std::string file = path("a_file");
  std::ofstream(file) << "x";
  const auto r = run("eval '" + kGarfield + "' -o '" + file + "/report' -q");
  EXPECT_EQ(r.exit_code, 4) << r.output;
  EXPECT_NE(r.output.find("cannot create directory " + file + "/report: Not a directory"), std::string::npos)
      << r.output;
}

TEST_F(RenderCliTest, EvalOfACutRecordingEvaluatesTheEventsBeforeTheFault) {
  // A raw recording cut inside a record (every estimator run stops at the
  // fault) and an augmented .bin cut the same way (the lifetimes of the file).
  const std::string aedat2 = kData + "/aedat2/alex_walking_again.aedat";
  fs::copy_file(aedat2, path("cut.aedat"));
  fs::resize_file(path("cut.aedat"), 300'001);
  ASSERT_EQ(run("process '" + kGarfield + "' -o '" + path("g.bin") + "' --to 0.2 -q").exit_code, 0);
  fs::copy_file(path("g.bin"), path("cut.bin"));
  fs::resize_file(path("cut.bin"), fs::file_size(path("g.bin")) - 7);
  ASSERT_EQ(run("process '" + kGarfield + "' -o '" + path("cut.csv") + "' --to 0.2 -q").exit_code, 0);
  std::ofstream(path("cut.csv"), std::ios::app) << "garbage\n";
  for (const std::string cut : {"cut.aedat", "cut.bin", "cut.csv"}) {
    const std::string dir = path("ev_" + cut);
    const auto r = run("eval '" + path(cut) + "' -o '" + dir + "' -q");
    EXPECT_EQ(r.exit_code, 3) << r.output;
    EXPECT_NE(r.output.find("holds the evaluation of the"), std::string::npos) << r.output;
    EXPECT_TRUE(fs::exists(dir + "/runs.csv")) << cut;
    // The compare frame of the events before the fault (the fault in the sampling skipped it).
    EXPECT_TRUE(fs::exists(dir + "/compare_frame.png")) << cut;
    std::ifstream html(dir + "/summary.html");
    const std::string text((std::istreambuf_iterator<char>(html)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("stopped by an input fault"), std::string::npos) << cut;
  }
}

// A selection of no event, evaluated into a folder an earlier run wrote: the
// earlier compare frame is removed (it stayed beside this run's empty report)
// and no time range is made up (it said "t = 0 .. 0 us (0.000000 s long)").
TEST_F(RenderCliTest, EvalOfNoEventLeavesNoEarlierCompareFrameAndNoTimeRange) {
  const std::string dir = path("reused");
  ASSERT_EQ(run("eval '" + kGarfield + "' --to 0.1 -o '" + dir + "' -q").exit_code, 0);
  ASSERT_TRUE(fs::exists(dir + "/compare_frame.png"));
  const auto r = run("eval '" + kGarfield + "' --from 10 -o '" + dir + "'");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_FALSE(fs::exists(dir + "/compare_frame.png"));
  EXPECT_NE(r.output.find("time range                 no event\n"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("no instant sampled: no event to sample"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("s long)"), std::string::npos) << r.output;
}

// Events the frames leave out (outside a --sensor smaller than the events')
// are counted in the summary and summary.html; the sharpness covered the crop
// without a word, while the runs counted every event.
TEST_F(RenderCliTest, EvalSaysWhichEventsTheFramesLeftOut) {
  ASSERT_EQ(run("process '" + kGarfield + "' -o '" + path("g.csv") + "' --to 0.2 -q").exit_code, 0);
  auto r = run("eval '" + path("g.csv") + "' -o '" + path("whole") + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("not in the frames"), std::string::npos) << r.output;
  // The names eval refuses to write over its input are the files it writes.
  std::vector<std::string> written, named = evlife::render::eval::report_file_names();
  for (const auto& f : fs::directory_iterator(path("whole"))) written.push_back(f.path().filename().string());
  std::sort(written.begin(), written.end());
  std::sort(named.begin(), named.end());
  EXPECT_EQ(written, named);
  r = run("eval '" + path("g.csv") + "' -o '" + path("crop") + "' --sensor 64x64");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto at = r.output.find("not in the frames");
  ASSERT_NE(at, std::string::npos) << r.output;
  EXPECT_NE(r.output.find(" outside the sensor, 0 older than their pixel's event", at), std::string::npos) << r.output;
  std::ifstream html(path("crop") + "/summary.html");
  const std::string text((std::istreambuf_iterator<char>(html)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("Not in the frames (the runs count them): "), std::string::npos);
}

std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  bool quoted = false;
  for (char c : line) {
    if (c == '"') {
      quoted = !quoted;
    } else if (c == ',' && !quoted) {
      out.push_back(cell);
      cell.clear();
    } else {
      cell += c;
    }
  }
  out.push_back(cell);
  return out;
}

TEST_F(RenderCliTest, EvalLifetimeHistogramMatchesProcessOutput) {
  // The first 0.3 s of the 0.74 s recording (eval runs six configurations):
  // both commands read the same events.
  auto r = run("eval '" + kGarfield + "' -o '" + path("eval") + "' --to 0.3 --frame-at 0.2 -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* f : {"summary.html", "lifetime_histogram.png", "lifetime_histogram.csv", "prediction_error_cdf.png",
                        "prediction_error_cdf.csv", "velocity_histogram.png", "sharpness.png", "sharpness_summary.csv",
                        "runs.csv", "compare_frame.png"})
    EXPECT_TRUE(fs::exists(path("eval") + "/" + f)) << f;

  // Independent histogram: lifetimes from `evlife process` (default config = N 5, regularized).
  r = run("process '" + kGarfield + "' -o '" + path("g.csv") + "' --to 0.3 -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream csv(path("g.csv"));
  std::string line;
  std::getline(csv, line);
  const auto header = split_csv(line);
  std::size_t lifetime_col = 0;
  while (lifetime_col < header.size() && header[lifetime_col] != "lifetime") ++lifetime_col;
  ASSERT_LT(lifetime_col, header.size()) << line;
  std::map<long, long> expected;  // 0.2 ms bin -> count
  long non_noise = 0;
  while (std::getline(csv, line)) {
    const double l = std::stod(split_csv(line)[lifetime_col]);
    if (l <= 0.0) continue;
    ++non_noise;
    ++expected[static_cast<long>(std::floor(l / 200.0))];
  }
  ASSERT_GT(non_noise, 1000);

  std::ifstream hist(path("eval") + "/lifetime_histogram.csv");
  std::getline(hist, line);
  const auto cols = split_csv(line);
  std::size_t col = 0;
  while (col < cols.size() && cols[col] != "N=5, regularized") ++col;
  ASSERT_LT(col, cols.size()) << line;
  long total = 0;
  long bin = 0;
  while (std::getline(hist, line) && line[0] != '#') {
    const auto cells = split_csv(line);
    EXPECT_NEAR(std::stod(cells[1]) - std::stod(cells[0]), 0.2, 1e-9);  // 0.2 ms bins (paper Fig. 10)
    const long n = std::stol(cells[col]);
    EXPECT_EQ(n, expected.count(bin) ? expected[bin] : 0) << "bin " << bin;
    total += n;
    ++bin;
  }
  long beyond = 0;
  for (const auto& [b, n] : expected)
    if (b >= bin) beyond += n;
  EXPECT_EQ(total + beyond, non_noise);
}

// The medians eval reports (runs.csv, its summary) are those of the values,
// within the +-1.2 % of the summaries of process and info, not the upper edge
// of the plots' 0.2 ms (0.1 ms) bin that holds them (7.40 ms for 7.34).
// What has no value is said so, not 0: the share of predictions below 10 ms
// of a run without a prediction, the edge thickness of an image without an
// edge ("0.0 %" and "0.00 px", read as none close and perfectly sharp).
TEST_F(RenderCliTest, EvalSaysNaWhereAFigureHasNoValue) {
  auto r = run("eval '" + kData + "/rosbag/test_data_mono_cd' -o '" + path("mono") + "'");  // 100 events, no prediction
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("with a prediction   0.0 %, median lifetime       n/a, |pred. err| < 10 ms:     n/a"),
            std::string::npos)
      << r.output;
  std::string runs = evlife::test::read_text_file(path("mono") + "/runs.csv");
  EXPECT_NE(runs.find(",0,nan,nan,nan,"), std::string::npos) << runs;  // predictions, medians, share below 10 ms
  // Every run is a column of the CDF, empty without a prediction (the runs were left out unsaid).
  const std::string cdf = evlife::test::read_text_file(path("mono") + "/prediction_error_cdf.csv");
  EXPECT_EQ(cdf.substr(0, cdf.find('\n')),
            "abs_error_ms,\"N=3, not regularized\",\"N=3, regularized\",\"N=5, not regularized\",\"N=5, regularized\","
            "\"N=7, not regularized\",\"N=7, regularized\"");
  EXPECT_NE(cdf.find("\n0.1,,,,,,\n"), std::string::npos) << cdf.substr(0, 300);
  r = run("eval '" + kData + "/prophesee_dat/NCARS_obj_004397_td.dat' -o '" + path("ncars") + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("fixed window 1 ms      0.0 %       n/a"), std::string::npos) << r.output;
  const std::string sharpness = evlife::test::read_text_file(path("ncars") + "/sharpness.csv");
  EXPECT_NE(sharpness.find("fixed window 1 ms,47,0,0,0,,"), std::string::npos) << sharpness;  // no edge pixel
}

TEST_F(RenderCliTest, EvalMediansAreTheValuesNotTheirBinsEdges) {
  auto r = run("process '" + kGarfield + "' -o '" + path("g.csv") + "' --to 0.3 -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run("eval '" + path("g.csv") + "' -o '" + path("eval") + "' -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream csv(path("g.csv"));
  std::string line;
  std::getline(csv, line);
  std::vector<double> lifetimes, errors, ratios;
  while (std::getline(csv, line)) {
    const auto cells = split_csv(line);
    const double lifetime = std::stod(cells.at(4));
    const bool predicted = cells.size() > 7 && !cells[7].empty();
    if (predicted) errors.push_back(std::fabs(std::stod(cells[7])));
    if (lifetime <= 0.0) continue;
    lifetimes.push_back(lifetime);
    if (predicted) ratios.push_back(std::fabs(std::stod(cells[7])) / lifetime);
  }
  ASSERT_GT(lifetimes.size(), 1000u);
  ASSERT_GT(errors.size(), 1000u);
  const auto median = [](std::vector<double> v) {  // nearest rank, as the summaries
    std::sort(v.begin(), v.end());
    return v[(v.size() + 1) / 2 - 1];
  };
  std::ifstream runs(path("eval") + "/runs.csv");
  std::getline(runs, line);
  const auto header = split_csv(line);
  std::getline(runs, line);
  const auto row = split_csv(line);
  const auto column = [&](const std::string& name) {
    const auto at = std::find(header.begin(), header.end(), name);
    EXPECT_NE(at, header.end()) << name;
    return std::stod(row.at(static_cast<std::size_t>(at - header.begin())));
  };
  EXPECT_NEAR(column("median_lifetime_ms"), median(lifetimes) / 1000.0, 0.012 * median(lifetimes) / 1000.0);
  EXPECT_NEAR(column("median_abs_error_ms"), median(errors) / 1000.0, 0.012 * median(errors) / 1000.0);
  EXPECT_NEAR(column("median_abs_error_over_lifetime"), median(ratios), 0.012 * median(ratios));
}

// `run --frames` draws the frames of `evlife render`, upscaling included, on
// any sensor (it kept FrameStyle's 4x: 1484x1086 px for render's 446x306).
TEST_F(RenderCliTest, RunDrawsRendersFramesOnAnySensor) {
  ASSERT_EQ(run("synth -q --scene edges-bar --sensor 346x260 --duration 0.3 -o '" + path("wide.h5") + "'").exit_code, 0);
  ASSERT_EQ(run("render '" + path("wide.h5") + "' -q -o '" + path("by_render") + "' --at 0.25").exit_code, 0);
  ASSERT_EQ(run("run '" + path("wide.h5") + "' -q --frames '" + path("by_run") + "' --fps 0 --at 0.25").exit_code, 0);
  const std::string name = "/frame_000000_t0.250000s.png";
  const std::string drawn = evlife::test::read_text_file(path("by_render") + name);
  ASSERT_GT(drawn.size(), 1000u);
  EXPECT_TRUE(drawn == evlife::test::read_text_file(path("by_run") + name));
}

// A corrupt time that jumps ahead (event 1000 at 50 s, its successors at
// 50 ms on) ends render's reading before an instant after 50 ms as a later
// event would: the frame lacked the events behind it and render exited 0
// (a review helper's byte changed in a Prophesee .dat; `process` says exit 3
// of the same file). Now the event after the one that ended the reading is
// read too: exit 3 naming it. A real gap (the outlier last) stays exit 0.
TEST_F(RenderCliTest, ACorruptTimeAheadOfTheInstantsIsAnInputErrorNotAShortFrame) {
  const std::string csv = path("jump.csv");
  {
    std::ofstream f(csv);
    for (int i = 0; i < 2000; ++i)
      f << (i % 64) << ',' << (i / 64) % 64 << ",1," << (i == 1000 ? 50'000'000 : i * 50) << '\n';
  }
  for (const std::string at : {"--at 0.06", "--fps 100 --to 0.06"}) {
    const auto r = run("render '" + csv + "' -o '" + path("jump") + "' " + at + " -q");
    EXPECT_EQ(r.exit_code, 3) << at << "\n" << r.output;
    EXPECT_NE(r.output.find("(event index 1001"), std::string::npos) << at << "\n" << r.output;
  }
  const std::string gap = path("gap.csv");
  write_events_then_outlier(gap, 50'000'000);  // 2000 events, then one at 50 s: a real gap, the file's end
  const auto r = run("render '" + gap + "' -o '" + path("gap.png") + "' --at 0.06 -q");
  EXPECT_EQ(r.exit_code, 0) << r.output;
}

// A frame folder used twice: the frames of the earlier run that this one did
// not replace are counted in a warning (a video of the folder would mix them
// in); a run that replaces every one of them is silent, and so is `run`'s.
TEST_F(RenderCliTest, AFrameFolderUsedTwiceWarnsOfTheEarlierFramesLeft) {
  const std::string dir = path("frames");
  auto r = run("render '" + kGarfield + "' -o '" + dir + "' --fps 10 --to 0.5 -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("earlier run"), std::string::npos) << r.output;
  r = run("render '" + kGarfield + "' -o '" + dir + "' --fps 10 --to 0.5 -q");  // the same frames again
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("earlier run"), std::string::npos) << r.output;
  r = run("render '" + kGarfield + "' -o '" + dir + "' --fps 10 --to 0.2 -q");  // 3 of the 6 again
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("also holds 3 frame_*.png of an earlier run"), std::string::npos) << r.output;
  r = run("run '" + kGarfield + "' --frames '" + dir + "' --fps 10 -q");  // every instant of the file
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("earlier run"), std::string::npos) << r.output;
  r = run("run '" + kGarfield + "' --frames '" + dir + "' --fps 20 -q");  // other instants: all 8 left
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("evlife run: warning:"), std::string::npos) << r.output;
}

// A timestamp outlier far after the recording: --fps without --to draws the
// empty frames up to it (the frame rate's meaning), but says so before the
// first of them, with the way out; a gap under the notice's size is silent.
// run --fps says it too (from its monitor thread, before the frames).
TEST_F(RenderCliTest, AFrameRateWarnsOfALongStretchWithoutEventsAhead) {
  const std::string csv = path("outlier.csv");
  write_events_then_outlier(csv, 100'000'000);  // 100 s: 99.9 s without an event
  const std::string warning = "no event from 0.272727 s to 100.000000 s (the next event): 1097 empty frames";
  const struct {
    std::string args;
    bool warns;
  } cases[] = {
      {"render '" + csv + "' -o '" + path("gap") + "' --fps 11 --scale 1 -q", true},
      {"render '" + csv + "' -o '" + path("gap_to") + "' --fps 11 --to 0.5 --scale 1 -q", false},
      {"render '" + csv + "' -o '" + path("gap_slow") + "' --fps 5 --scale 1 -q", false},  // 500 frames
      {"run '" + csv + "' --frames '" + path("gap_run") + "' --fps 11 -q", true},
  };
  for (const auto& c : cases) {
    const auto r = run(c.args);
    ASSERT_EQ(r.exit_code, 0) << c.args << "\n" << r.output;
    EXPECT_EQ(r.output.find(warning) != std::string::npos, c.warns) << c.args << "\n" << r.output;
  }
  // The sensor is 64x32: at scale 1 its panels are lower than the colour
  // legend, which OpenCV refused to copy (exit 1, "unexpected error").
  const auto r = run("render '" + csv + "' -o '" + path("small.png") + "' --at 0.05 --scale 1 --mode compare -q");
  EXPECT_EQ(r.exit_code, 0) << r.output;
}

// `run --fps` skips a stretch without events of 100,000 frames or more (a
// timestamp outlier ten years ahead: 9.5 G empty frames at 30 fps), counted
// and said, as `render` stops before it; every event is written. Before, the
// render thread drew on through the gap and the run never ended. Each long
// stretch is said, not only the first.
TEST_F(RenderCliTest, ARunSkipsEveryHugeGapAndSaysEachLongOne) {
  const std::string csv = path("decade.csv");
  write_events_then_outlier(csv, 315'360'000'000'000);
  auto r = evlife::test::run_cli("timeout", "-k 5 60 '" + kCli + "' run '" + csv + "' --frames '" + path("decade") +
                                               "' --fps 30 -o '" + path("decade.bin") + "'",
                                 dir_.path() / "cli.log");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("9460799996 empty frames at 30 fps come first; a timestamp outlier? Skipped, not drawn"),
            std::string::npos) << r.output;
  EXPECT_NE(r.output.find("(9460799996 of stretches without events skipped"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("output : 2001 events to the writer"), std::string::npos) << r.output;
  const std::string gaps = path("gaps.csv");
  {
    std::ofstream f(gaps);
    f << "x,y,t,p,lifetime,vx,vy,prediction_error\n0,0,0,1,1000,0,0,\n1,1,1000,1,1000,0,0,\n"
      << "1,0,1100000000,1,1000,0,0,\n0,1,201100000000,1,1000,0,0,\n";
  }
  r = run("run '" + gaps + "' --sensor 4x2 --frames '" + path("gaps") + "' --fps 1");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("1098 empty frames at 1 fps come first"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("199999 empty frames at 1 fps come first; a timestamp outlier? Skipped"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("frames : 1102 written"), std::string::npos) << r.output;  // 1100 s and 201100 s drawn
  // Three huge stretches in a row: each said, each event's frame drawn (before: one notice, "2 more
  // such stretches before it", and the events between them in no frame).
  const std::string three = path("three.csv");
  {
    std::ofstream f(three);
    f << "x,y,t,p,lifetime,vx,vy,prediction_error\n";
    for (const long long t : {0LL, 1000LL, 1'000'000'000'000LL, 2'000'000'000'000LL, 3'000'000'000'000LL})
      f << "0,0," << t << ",1,1000,0,0,\n";
  }
  r = run("run '" + three + "' --sensor 4x2 --frames '" + path("three") + "' --fps 1");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  std::size_t said = 0;
  for (auto at = r.output.find("Skipped, not drawn"); at != std::string::npos; at = r.output.find("Skipped, not drawn", at + 1))
    ++said;
  EXPECT_EQ(said, 3u) << r.output;
  EXPECT_TRUE(fs::exists(path("three") + "/frame_000004_t3000000.000000s.png")) << r.output;
  EXPECT_TRUE(fs::exists(path("three") + "/frame_000003_t2000000.000000s.png")) << r.output;
}

// Ctrl-C while `run` draws a long stretch without events (under the skip's
// 100,000 frames, at 1280x720: minutes of frames) ends the run at once: the
// frames not drawn yet are skipped and counted, every event is written.
// Before, a signal that came while it drew the gap's frames stepped through
// them one by one.
TEST_F(RenderCliTest, CtrlCEndsARunDrawingThroughAGap) {
  const std::string csv = path("hour.csv");
  write_events_then_outlier(csv, 3'300'000'000);  // 99,000 frames at 30 fps
  const auto r = evlife::test::run_cli("timeout", "--preserve-status -s INT -k 60 5 '" + kCli + "' run '" + csv +
                                                      "' --sensor 1280x720 --frames '" + path("hour") +
                                                      "' --fps 30 -o '" + path("hour.bin") + "'",
                                       dir_.path() / "cli.log");
  EXPECT_EQ(r.exit_code, 130) << r.output;  // 137 if it had to be killed
  EXPECT_NE(r.output.find("more not drawn: stopped"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("all 2001 accepted events were written"), std::string::npos) << r.output;
}

// An evlife output whose times reach the ends of the clock (a corrupt
// timestamp at 2^63 - 1 us): render stops before the gap as before any other
// (it hung at 90 % CPU, deaf to signals: a frame's instant wrapped), and one
// event there is one frame (exit 1, "render times must not decrease").
TEST_F(RenderCliTest, TimesAtTheEndOfTheClockAreAGapOrAFrameAsAnyOther) {
  const std::string csv = path("clock_end.csv");
  {
    std::ofstream f(csv);
    f << "x,y,t,p,lifetime,vx,vy,prediction_error\n";
    for (int i = 0; i < 2000; ++i) f << (i % 64) << ',' << (i / 64) % 64 << ',' << i * 50 << ",1,1000,0,0,\n";
    f << "5,5,9223372036854775807,1,1000,0,0,\n";
  }
  auto r = run("render '" + csv + "' --sensor 64x64 -o '" + path("end") + "'");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("a timestamp outlier? Stopped before them"), std::string::npos) << r.output;
  EXPECT_GE(std::distance(fs::directory_iterator(path("end")), fs::directory_iterator{}), 1) << r.output;
  const std::string single = path("single.csv");
  std::ofstream(single) << "x,y,t,p,lifetime,vx,vy,prediction_error\n5,5,9223372036854775807,1,1000,0,0,\n";
  r = run("render '" + single + "' --sensor 64x64 -o '" + path("single") + "'");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("frames              1 "), std::string::npos) << r.output;
}

// Ctrl-C in synth closes a complete, shorter file and says how much it holds
// (before: killed mid-line, exit by signal); in eval it says that nothing was
// written (the report needs every run) and exits 130 (before: killed silently).
TEST_F(RenderCliTest, CtrlCInSynthAndEvalIsACleanStop) {
  const std::string scene = path("long.txt");
  auto r = evlife::test::run_cli("timeout", "--preserve-status -s INT -k 5 1 '" + kCli + "' synth -o '" + scene +
                                                "' --scene large --sensor 640x480 --duration 100",
                                 dir_.path() / "cli.log");
  ASSERT_EQ(r.exit_code, 130) << r.output;
  const auto held = r.output.find("events (a complete file, cut short)");
  ASSERT_NE(held, std::string::npos) << r.output;
  const auto count_at = r.output.rfind(", ", held) + 2;
  const std::string count = r.output.substr(count_at, held - 1 - count_at);
  const auto info = run("info '" + scene + "'");
  EXPECT_EQ(info.exit_code, 0) << info.output;  // every line whole
  std::string with_commas;
  for (std::size_t i = 0; i < count.size(); ++i) {
    if (i > 0 && (count.size() - i) % 3 == 0) with_commas += ',';
    with_commas += count[i];
  }
  EXPECT_NE(info.output.find("events     " + with_commas + " ("), std::string::npos) << count << "\n" << info.output;

  const std::string h5 = path("eval_input.h5");
  ASSERT_EQ(run("synth -o '" + h5 + "' --scene large --sensor 320x240 --duration 1 -q").exit_code, 0);
  r = evlife::test::run_cli("timeout", "--preserve-status -s INT -k 60 1 '" + kCli + "' eval '" + h5 + "' -o '" +
                                           path("report") + "' -q",
                            dir_.path() / "cli.log");
  EXPECT_EQ(r.exit_code, 130) << r.output;
  EXPECT_NE(r.output.find("interrupted: nothing written to"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(path("report") + "/summary.html"));
}

// eval's compare frame is drawn at --frame-at itself (before: the last sample
// instant not after it, 0.10 s for 0.12 s), or at the last event when the
// recording ends first; a recording shorter than --sample-every has no
// sharpness instant, and says so (before: "completeness 100.0 %" over 0
// instants, and summary.html linking a compare frame never drawn).
TEST_F(RenderCliTest, EvalDrawsTheCompareFrameWhereAskedAndSaysWhenNothingWasSampled) {
  const std::string scene = path("short.txt");
  ASSERT_EQ(run("synth -q --duration 0.3 -o '" + scene + "'").exit_code, 0);
  auto r = run("eval '" + scene + "' -o '" + path("at") + "' --frame-at 0.12 -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(evlife::test::read_text_file(path("at") + "/summary.html").find("Compare frame (t = 0.120 s)"),
            std::string::npos);
  r = run("eval '" + scene + "' -o '" + path("long") + "' --sample-every 1s");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("sharpness: no instant sampled: the recording (0.29"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("over 0 instants"), std::string::npos) << r.output;
  EXPECT_TRUE(std::filesystem::exists(path("long") + "/compare_frame.png"));
  const std::string html = evlife::test::read_text_file(path("long") + "/summary.html");
  EXPECT_NE(html.find("Compare frame (t = 0.300 s)"), std::string::npos);  // the last event, before 0.5 s
  EXPECT_NE(evlife::test::read_text_file(path("long") + "/sharpness_summary.csv").find("\nlifetime (ours),0,,,,,,\n"),
            std::string::npos);
}

// A recording without an edge anywhere (isolated events 4 px apart): no fixed
// window shows an edge pixel, so completeness has no reference. It was 100 %,
// and the score the thin-edge share alone; now "n/a" and empty CSV fields.
TEST_F(RenderCliTest, EvalSaysCompletenessHasNoReferenceWhereNoWindowShowsAnEdge) {
  const std::string csv = path("isolated.csv");
  {
    std::ofstream out(csv);
    out << "x,y,t,p\n";
    for (int i = 0; i < 3000; ++i) out << 4 * (i % 30) << "," << 4 * ((i / 30) % 30) << "," << 1000 + 100 * i << ",1\n";
  }
  const auto r = run("eval '" + csv + "' -o '" + path("isolated") + "' --sensor 128x128");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("over "), std::string::npos) << r.output;  // instants were sampled
  EXPECT_EQ(r.output.find("100.0 %  1.000"), std::string::npos) << r.output;
  // No edge pixel either: its mean thickness has no value too (it said 0.00 px).
  EXPECT_NE(r.output.find("0.0 %       n/a      n/a  n/a\n"), std::string::npos) << r.output;
  const std::string summary = evlife::test::read_text_file(path("isolated") + "/sharpness_summary.csv");
  EXPECT_NE(summary.find("\nlifetime (ours),"), std::string::npos) << summary;
  EXPECT_NE(summary.find(",,\n"), std::string::npos) << summary;  // completeness and score: no figure
  EXPECT_EQ(summary.find("nan"), std::string::npos) << summary;
  const std::string html = evlife::test::read_text_file(path("isolated") + "/summary.html");
  EXPECT_NE(html.find("<td>n/a</td><td>n/a</td></tr>"), std::string::npos);
}

// A pause of an hour (an outlier's timestamp, a recording resumed): its 72,000
// instants, where no fixed window draws a pixel, are counted, not sampled (they
// were rows of sharpness.csv, for minutes, deaf to Ctrl-C; 2^63 us never ended).
TEST_F(RenderCliTest, EvalCountsTheInstantsOfAPauseInsteadOfSamplingThem) {
  const std::string scene = path("scene.txt");
  ASSERT_EQ(run("synth -q --duration 0.3 -o '" + scene + "'").exit_code, 0);
  {
    std::ofstream(scene, std::ios::app) << "3600.000000 5 5 1\n3600.001000 6 6 1\n";
  }
  ASSERT_EQ(run("process -q '" + scene + "' --sensor 128x128 -o '" + path("paused.bin") + "'").exit_code, 0);
  const auto r = run("eval '" + path("paused.bin") + "' -o '" + path("ev") + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::size_t at = r.output.find("  over ");
  ASSERT_NE(at, std::string::npos) << r.output;
  const std::size_t instants = std::stoul(r.output.substr(at + 7));
  EXPECT_GE(instants, 6u) << r.output;  // 0.05 .. 0.30 s at least
  EXPECT_LE(instants, 8u) << r.output;
  EXPECT_NE(r.output.find(" instants of pauses (no fixed window draws a pixel), left out"), std::string::npos) << r.output;
  // One row per method and sampled instant.
  const std::string csv = evlife::test::read_text_file(path("ev") + "/sharpness.csv");
  EXPECT_EQ(static_cast<std::size_t>(std::count(csv.begin(), csv.end(), '\n')), 1 + 4 * instants);
}

// runs.csv of an augmented input leaves the estimator's options empty: the
// file does not say which made its lifetimes (it said window 0, not regularized).
TEST_F(RenderCliTest, RunsCsvOfAnAugmentedInputStatesNoEstimatorOptions) {
  ASSERT_EQ(run("process '" + kGarfield + "' -o '" + path("g.bin") + "' --to 0.1 -q").exit_code, 0);
  ASSERT_EQ(run("eval '" + path("g.bin") + "' -o '" + path("ev_aug") + "' -q").exit_code, 0);
  const std::string csv = evlife::test::read_text_file(path("ev_aug") + "/runs.csv");
  EXPECT_NE(csv.find("\n\"lifetimes from the file\",,,"), std::string::npos) << csv;
}

// An augmented CSV (it states no sensor) cut short: the sensor scan stopped
// at the fault before any frame, so render drew nothing (a recording in the
// same state got its frames). Now the frames before the fault, then the fault.
TEST_F(RenderCliTest, ATruncatedAugmentedCsvKeepsTheFramesBeforeTheFault) {
  auto r = run("process '" + kGarfield + "' -o '" + path("g.csv") + "' --to 0.3 -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string whole = evlife::test::read_text_file(path("g.csv"));
  {
    std::ofstream cut(path("cut.csv"), std::ios::binary);
    cut << whole.substr(0, whole.size() * 2 / 3 + 5);  // 0.2 s of events, then half a line
  }
  r = run("render '" + path("cut.csv") + "' -o '" + path("frames") + "' --fps 10 -q");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("truncated (the file ends inside it)"), std::string::npos) << r.output;
  ASSERT_TRUE(fs::is_directory(path("frames"))) << r.output;
  const auto frames = std::distance(fs::directory_iterator(path("frames")), fs::directory_iterator{});
  EXPECT_GE(frames, 1) << r.output;
  EXPECT_NE(r.output.find("the " + std::to_string(frames) + " frames before the fault were written"), std::string::npos)
      << r.output;
}

}  // namespace
