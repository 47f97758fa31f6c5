// `evlife info` on a sample of every readable format: the event counts are
// the ones ../shared/data/PROVENANCE.md states for each file (decoded by
// others), the sensor sizes the ones the files state.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "cli_runner.h"
#include "scratch_dir.h"

namespace {

namespace fs = std::filesystem;

const std::string kData = EVLIFE_SHARED_DATA_DIR;

struct Case {
  std::string file;
  std::string format;
  std::string events;  // as printed, with thousands separators
  std::string sensor;  // "" = not stated by the format
};

class CliInfo : public ::testing::Test {
 protected:
  evlife::test::CliRun run(const std::string& args) const {
    return evlife::test::run_cli(EVLIFE_CLI_PATH, args, dir_.path() / "cli.log");
  }
  const evlife::test::ScratchDir dir_{"test_cli_info"};
};

TEST_F(CliInfo, DescribesEverySharedSample) {
  const Case cases[] = {
      {"reference/stripes.mat", "mat", "340,394", ""},
      {"aedat2/alex_walking_again.aedat", "aedat2", "19,182", "128x128"},
      {"rpg_txt/slider_depth_events_chunk.txt", "rpg-text", "50,000", ""},
      {"aedat4/sample.aedat4", "aedat4", "111,954", "320x240"},
      {"evt2/evt2_sample.raw", "evt2", "539,481", "640x480"},
      {"evt3/evt3_sample.raw", "evt3", "219,596", "1280x720"},
      {"prophesee_dat/NCARS_obj_004397_td.dat", "prophesee-dat", "4,407", ""},
      {"rosbag/test_data_evt3_trigger", "rosbag2", "82,469 (41,439 ON, 41,030 OFF)", "1280x720"},
      {"rosbag/test_data_libcaer_rollover", "rosbag2", "334,331 (181,908 ON, 152,423 OFF)", "640x480"},
      {"rosbag/test_data_mono_cd", "rosbag2", "100 (50 ON, 50 OFF)", "640x480"},
  };
  for (const Case& c : cases) {
    const auto r = run("info '" + kData + "/" + c.file + "'");
    EXPECT_EQ(r.exit_code, 0) << c.file << "\n" << r.output;
    EXPECT_NE(r.output.find("format     " + c.format + " ("), std::string::npos) << c.file << "\n" << r.output;
    EXPECT_NE(r.output.find("events     " + c.events), std::string::npos) << c.file << "\n" << r.output;
    if (!c.sensor.empty()) {
      EXPECT_NE(r.output.find("sensor     " + c.sensor + " (stated"), std::string::npos) << c.file << "\n" << r.output;
    }
  }
}

TEST_F(CliInfo, BagTopicsTriggersAndDuration) {
  const auto r = run("info '" + kData + "/rosbag/test_data_evt3_trigger'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("triggers   2\n"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("* /event_camera/events"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("event_camera_msgs/msg/EventPacket"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("105 messages"), std::string::npos) << r.output;
  // 14.224870 .. 15.476187 s of sensor time (PROVENANCE.md).
  EXPECT_NE(r.output.find("time       14224870 .. 15476187 us, duration 1.251317 s"), std::string::npos)
      << r.output;
}

TEST_F(CliInfo, CsvAndHdf5AndErrors) {
  const fs::path csv = dir_.path() / "mv.csv";
  std::ofstream(csv) << "10,20,1,1000\n11,21,0,1500\n639,479,1,2250\n";
  auto r = run("info '" + csv.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("format     csv ("), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("events     3 (2 ON, 1 OFF)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("the events span 640x480"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("1000 .. 2250 us"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("gap        longest without events 0.000750 s, after t = 1500 us"), std::string::npos)
      << r.output;
  // One event, or every event at one time: there is no gap "after t = 0 us".
  const fs::path one = dir_.path() / "one.csv", tie = dir_.path() / "tie.csv";
  std::ofstream(one) << "10,20,1,5\n";
  std::ofstream(tie) << "10,20,1,7\n11,20,1,7\n";
  r = run("info '" + one.string() + "'");
  EXPECT_NE(r.output.find("gap        none: one event\n"), std::string::npos) << r.output;
  r = run("info '" + tie.string() + "'");
  EXPECT_NE(r.output.find("gap        longest without events 0.000000 s, after t = 7 us"), std::string::npos) << r.output;
  const fs::path h5 = dir_.path() / "mv.h5";
  ASSERT_EQ(run("convert '" + csv.string() + "' '" + h5.string() + "' -q").exit_code, 0);
  r = run("info '" + h5.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("format     hdf5 ("), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("\nlayout     evlife\n"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("events     3 (2 ON, 1 OFF)"), std::string::npos) << r.output;
  // A bad line: the events before it are counted, then the error, exit 3.
  std::ofstream(csv) << "10,20,1,1000\n11,21,0,1500\n639,479,1,22x0\n";
  r = run("info '" + csv.string() + "'");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("events     2 (1 ON, 1 OFF)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("line 3"), std::string::npos) << r.output;
  EXPECT_EQ(run("info").exit_code, 2);
  EXPECT_EQ(run("info '" + dir_.file("missing.raw") + "'").exit_code, 3);
  // Timestamps that go backwards: every event described, the first such event
  // named as the other commands name it, and exit 3 (they stop there; before,
  // "somewhere" and exit 0).
  const fs::path txt = dir_.path() / "backwards.txt";
  std::ofstream(txt) << "1.0 2 3 1\n0.5 2 3 1\n2.0 2 3 0\n1.5 1 1 0\n";
  r = run("info '" + txt.string() + "'");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("events     4 (2 ON, 2 OFF)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("2 events earlier than one before them"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(txt.string() + ": timestamp goes backwards: 500000 us after 1000000 us (event index 1, byte offset 10)"),
            std::string::npos)
      << r.output;
}

// evlife's own outputs: their events and the lifetimes they hold, with the
// very figures `process` printed when it wrote them (before, the .bin was "an
// unknown format" and the .csv passed for plain x,y,t,p events).
TEST_F(CliInfo, EvlifeOutputsShowTheirLifetimes) {
  const std::string in = kData + "/reference/stripes.mat";
  const auto line = [](const std::string& text, const std::string& head) {
    const auto at = text.find(head);
    return at == std::string::npos ? std::string("(no " + head + ")") : text.substr(at, text.find('\n', at) - at);
  };
  for (const std::string ext : {".bin", ".csv"}) {
    const fs::path out = dir_.path() / ("stripes" + ext);
    const auto p = run("process '" + in + "' -o '" + out.string() + "'");
    ASSERT_EQ(p.exit_code, 0) << p.output;
    const auto r = run("info '" + out.string() + "'");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("format     augmented-" + ext.substr(1) + " (evlife's output"), std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("events     340,394 ("), std::string::npos) << r.output;
    for (const std::string head : {"labelled noise", "lifetime (edges)", "with a prediction", "|prediction error|"}) {
      EXPECT_EQ(line(r.output, head), line(p.output, head)) << ext << "\n" << r.output << "\n" << p.output;
    }
    EXPECT_EQ(r.output.find("wall time"), std::string::npos) << r.output;
  }
  // Cut inside a record: the figures of the records before it, then the error.
  const fs::path bin = dir_.path() / "stripes.bin";
  fs::resize_file(bin, fs::file_size(bin) - 5);
  auto r = run("info '" + bin.string() + "'");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("events     340,393 ("), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("truncated"), std::string::npos) << r.output;
  // Cut inside the header: said so, not "unknown format".
  fs::resize_file(bin, 12);
  r = run("info '" + bin.string() + "'");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("truncated: the header needs"), std::string::npos) << r.output;
}

// Times that span the whole clock (an evlife output written from any int64
// times): the durations of info, process's summary and eval are positive (the
// int64 difference overflowed: "duration -9223372036854.775391 s").
TEST_F(CliInfo, ATimeSpanOfTheWholeClockHasAPositiveDuration) {
  const fs::path csv = dir_.path() / "span.csv";
  std::ofstream(csv) << "x,y,t,p,lifetime,vx,vy,prediction_error\n1,1,-5,1,100,0,0,\n"
                     << "2,2,9223372036854775807,1,100,0,0,\n";
  const auto info = run("info '" + csv.string() + "'");
  EXPECT_EQ(info.exit_code, 0) << info.output;
  EXPECT_NE(info.output.find("duration 9223372036854.775"), std::string::npos) << info.output;
  EXPECT_EQ(info.output.find(" -9223372036854"), std::string::npos) << info.output;
  const auto eval = run("eval '" + csv.string() + "' -o '" + (dir_.path() / "ev").string() + "' --sensor 8x8");
  EXPECT_EQ(eval.exit_code, 0) << eval.output;
  EXPECT_NE(eval.output.find("(9223372036854.775"), std::string::npos) << eval.output;
  EXPECT_EQ(eval.output.find("-9223372036854"), std::string::npos) << eval.output;
}

// An output whose events span more than any camera (a stray coordinate) or
// whose header states such a sensor: `info` describes it without per-pixel
// counts (they would take gigabytes: the process was killed), `render` says
// why it cannot draw it and how to (--sensor).
TEST_F(CliInfo, AnOutputSpanningMoreThanAnyCameraIsDescribedAndRenderSaysWhy) {
  const fs::path csv = dir_.path() / "stray.csv";
  std::ofstream(csv) << "x,y,t,p,lifetime,vx,vy,prediction_error\n1,1,1,1,0,0,0,\n"
                     << "60000,60000,500000,1,0,0,0,\n2,2,1000000,1,0,0,0,\n";
  const auto info = run("info '" + csv.string() + "'");
  EXPECT_EQ(info.exit_code, 0) << info.output;
  EXPECT_NE(info.output.find("the events span 60001x60001"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("labelled noise      100.0 % (3 events)"), std::string::npos) << info.output;
  EXPECT_EQ(info.output.find("pixels >="), std::string::npos) << info.output;
  const fs::path png = dir_.path() / "stray.png";
  const auto refused = run("render '" + csv.string() + "' -o '" + png.string() + "' --at 0.9");
  EXPECT_EQ(refused.exit_code, 3) << refused.output;
  EXPECT_NE(refused.output.find(csv.string() + ": has events spanning 60001x60001, more than any camera"),
            std::string::npos)
      << refused.output;
  const auto drawn = run("render '" + csv.string() + "' -o '" + png.string() + "' --at 0.9 --sensor 320x240");
  EXPECT_EQ(drawn.exit_code, 0) << drawn.output;
  EXPECT_NE(drawn.output.find("ignored             1 outside the sensor"), std::string::npos) << drawn.output;

  // `convert` of it to .bin states no sensor (0x0), said so; then the same
  // events under a header stating a 60001x60001 sensor (a corrupt header).
  const fs::path bin = dir_.path() / "stray.bin";
  ASSERT_EQ(run("convert '" + csv.string() + "' '" + bin.string() + "'").exit_code, 0);
  const auto unstated = run("info '" + bin.string() + "'");
  EXPECT_EQ(unstated.exit_code, 0) << unstated.output;
  EXPECT_NE(unstated.output.find("the events span 60001x60001"), std::string::npos) << unstated.output;
  {
    std::fstream f(bin, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(16);  // width, height: little-endian uint32 (README, *Binary augmented event format*)
    const char sides[8] = {'\x61', '\xea', 0, 0, '\x61', '\xea', 0, 0};  // 60001 = 0xea61
    f.write(sides, sizeof sides);
  }
  const auto huge = run("info '" + bin.string() + "'");
  EXPECT_EQ(huge.exit_code, 0) << huge.output;
  EXPECT_NE(huge.output.find("sensor     60001x60001 (stated by the file)"), std::string::npos) << huge.output;
  EXPECT_EQ(huge.output.find("pixels >="), std::string::npos) << huge.output;
}

}  // namespace

class CliFindings : public ::testing::Test {
 protected:
  evlife::test::CliRun run(const std::string& args) const {
    return evlife::test::run_cli(EVLIFE_CLI_PATH, args, dir_.path() / "cli.log");
  }
  std::string file(const std::string& name) const { return (dir_.path() / name).string(); }
  const evlife::test::ScratchDir dir_{"test_cli_findings"};
};

// An HDF5 file whose event lies outside the sensor it states: `info` read it
// unchecked and said nothing (exit 0) where the other commands refused it; now
// the reader names the event as for every format that states a sensor.
TEST_F(CliFindings, AnHdf5EventOutsideItsStatedSensorIsAnInputErrorForInfoToo) {
  std::ofstream(file("oos.txt")) << "0.1 3 4 1\n0.15 500 4 0\n0.2 3 4 1\n";
  ASSERT_EQ(run("convert '" + file("oos.txt") + "' '" + file("oos.h5") + "' --sensor 128x128 --unchecked -q").exit_code,
            0);
  for (const char* name : {"info", "convert"}) {
    const std::string command = name;
    const auto r = run(command + " '" + file("oos.h5") + "'" + (command == "convert" ? " '" + file("o.txt") + "'" : ""));
    EXPECT_EQ(r.exit_code, 3) << command << r.output;
    EXPECT_NE(r.output.find("event at (x 500, y 4) is outside the 128x128 sensor the file states (event index 1)"),
              std::string::npos) << command << r.output;
  }
}

// --from/--to that select no event: `process`, `run` and `eval` warned,
// `convert` and `info` said "0 events" alone.
TEST_F(CliFindings, AnEmptySelectionIsWarnedOfByEveryCommand) {
  const std::string slider = std::string(EVLIFE_SHARED_DATA_DIR) + "/rpg_txt/slider_depth_events_chunk.txt";
  for (const std::string& args : {"convert '" + slider + "' '" + file("p.txt") + "' --from 10",
                                 "info '" + slider + "' --from 10", "process '" + slider + "' -o '" + file("p.bin") +
                                 "' --from 10"}) {
    const auto r = run(args);
    EXPECT_EQ(r.exit_code, 0) << args << r.output;
    EXPECT_NE(r.output.find(": warning: no event of " + slider + " within --from/--to"), std::string::npos)
        << args << r.output;
  }
}

// The optional first line "width height" of an RPG text file: told by its
// content (a pipe, another extension), not only by the name .txt.
TEST_F(CliFindings, AnRpgTextWithItsSensorLineIsToldByItsContent) {
  std::ofstream(file("wh.events")) << "240 180\n0.001 3 4 1\n0.002 5 6 0\n";
  const auto r = run("info '" + file("wh.events") + "'");  // (stdin, a pipe: the same sniff of the content)
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("format     rpg-text"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("sensor     240x180 (stated by the file)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("events     2 (1 ON, 1 OFF)"), std::string::npos) << r.output;
}

// Records the reader skips (EVT 3.0 events before the stream's first time
// base, a file cut mid-stream) are shown by `render` and `eval` too, as by
// `process`, `convert` and `run` (they were dropped unsaid).
TEST_F(CliFindings, RenderAndEvalShowTheRecordsTheReaderSkipped) {
  std::string bytes;
  {
    std::ifstream in(std::string(EVLIFE_SHARED_DATA_DIR) + "/evt3/evt3_sample.raw", std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  std::size_t header_end = 0;  // the '%' lines
  while (header_end < bytes.size() && bytes[header_end] == '%') header_end = bytes.find('\n', header_end) + 1;
  std::ofstream(file("mid.raw"), std::ios::binary) << bytes.substr(0, header_end) + bytes.substr(header_end + 20000);
  const std::string expected = "skipped records 192 (non-event records of the format: event-before-the-first-time-high 192)";
  auto r = run("process '" + file("mid.raw") + "' -o '" + file("m.bin") + "'");
  EXPECT_NE(r.output.find("  skipped records     192 (non-event records"), std::string::npos) << r.output;
  r = run("render '" + file("mid.raw") + "' -o '" + file("f.png") + "' --at 5ms");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("  skipped records     192 (non-event records of the format: event-before-the-first-time-high 192)"),
            std::string::npos) << r.output;
  r = run("eval '" + file("mid.raw") + "' -o '" + file("ev") + "'");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("; " + expected + " -> "), std::string::npos) << r.output;
  EXPECT_NE(evlife::test::read_text_file(file("ev") + "/summary.html").find(expected), std::string::npos);
}
