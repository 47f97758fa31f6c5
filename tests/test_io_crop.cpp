// Cropping and filtering at the source (ReaderOptions from_us / to_us /
// polarity; --from --to --polarity of every command reading events).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "scratch_dir.h"
#include "evlife/io/event_reader.h"

namespace {

namespace fs = std::filesystem;
using evlife::Event;
namespace io = evlife::io;

class IoCrop : public ::testing::Test {
 public:
  IoCrop() {
    // 10 events, t = 5000 + 1000 i µs, p alternating ON/OFF, x = i.
    std::ofstream out(csv());
    out << "x,y,t,p\n";
    for (int i = 0; i < 10; ++i) out << i << ",3," << 5000 + 1000 * i << "," << (i % 2 == 0 ? 1 : 0) << "\n";
  }

 protected:
  std::string csv() const { return dir_.file("ten.csv"); }
  std::vector<int> xs(const io::ReaderOptions& options, bool checked = true) const {
    const auto reader = checked ? io::open_event_reader(csv(), options)
                                : io::open_unchecked_event_reader(csv(), options);
    std::vector<Event> batch(3);  // small: filtering across read() calls
    std::vector<int> x;
    while (const std::size_t n = reader->read(batch))
      for (std::size_t i = 0; i < n; ++i) x.push_back(batch[i].x);
    return x;
  }
  evlife::test::CliRun run(const std::string& args) const {
    return evlife::test::run_cli(EVLIFE_CLI_PATH, args, dir_.path() / "cli.log");
  }
  const evlife::test::ScratchDir dir_{"test_io_crop"};
};

TEST_F(IoCrop, FromToRelativeToTheFirstEvent) {
  io::ReaderOptions o;
  o.from_us = 2000;
  o.to_us = 5000;
  EXPECT_EQ(xs(o), (std::vector<int>{2, 3, 4}));
  EXPECT_EQ(xs(o, false), (std::vector<int>{2, 3, 4}));
  io::ReaderOptions only_to;
  only_to.to_us = 1;
  EXPECT_EQ(xs(only_to), (std::vector<int>{0}));
  io::ReaderOptions beyond;
  beyond.from_us = 100'000;
  EXPECT_TRUE(xs(beyond).empty());
}

TEST_F(IoCrop, Polarity) {
  io::ReaderOptions on;
  on.polarity = io::PolarityFilter::on;
  EXPECT_EQ(xs(on), (std::vector<int>{0, 2, 4, 6, 8}));
  io::ReaderOptions off;
  off.polarity = io::PolarityFilter::off;
  off.from_us = 3000;
  EXPECT_EQ(xs(off), (std::vector<int>{3, 5, 7, 9}));
}

// The events --from or --polarity drop are checked as the ones kept: a step
// back or a pixel outside the sensor among them is an error naming the
// file's event index and offset (they were dropped before the checks: exit
// 0, or an error naming the index among the kept events).
TEST_F(IoCrop, DroppedEventsAreCheckedAndErrorsNameTheFilesIndex) {
  const std::string bad = dir_.file("bad.csv");
  {
    std::ofstream out(bad);
    out << "x,y,t,p\n";
    // 10 events as ten.csv, but event 3 (OFF) steps back.
    for (int i = 0; i < 10; ++i)
      out << i << ",3," << (i == 3 ? 4000 : 5000 + 1000 * i) << "," << (i % 2 == 0 ? 1 : 0) << "\n";
  }
  const auto fault_of = [&bad](const io::ReaderOptions& options) -> std::optional<io::ReadError> {
    const auto reader = io::open_event_reader(bad, options);
    std::vector<Event> batch(4);
    try {
      while (reader->read(batch) > 0) {
      }
    } catch (const io::ReadError& e) {
      return e;
    }
    return std::nullopt;
  };
  io::ReaderOptions from;
  from.sensor = evlife::SensorSize{16, 16};
  from.from_us = 5000;  // from event 5 on: the step back of event 3 lies before
  auto fault = fault_of(from);
  ASSERT_TRUE(fault);
  EXPECT_EQ(fault->event_index(), 3);
  EXPECT_NE(std::string(fault->what()).find("timestamp goes backwards"), std::string::npos) << fault->what();
  io::ReaderOptions off;
  off.sensor = evlife::SensorSize{16, 16};
  off.polarity = io::PolarityFilter::off;
  fault = fault_of(off);
  ASSERT_TRUE(fault);
  EXPECT_EQ(fault->event_index(), 3);  // the file's index, not the 2nd OFF event's 1
  EXPECT_GT(fault->byte_offset(), 0);
  // The command line as the user met it: exit 3, not 0.
  const auto r = run("process '" + bad + "' --sensor 16x16 --from 5ms -q -o '" + dir_.file("b.csv") + "'");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("event index 3"), std::string::npos) << r.output;
}

TEST_F(IoCrop, EveryCommandTakesTheFlags) {
  const std::string bag = std::string(EVLIFE_SHARED_DATA_DIR) + "/rosbag/test_data_mono_cd";
  // info: the mono bag holds 50 ON / 50 OFF events at t = 0..99 µs.
  auto r = run("info '" + bag + "' --polarity on --from 10us --to 60us");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("events     25 (25 ON, 0 OFF)"), std::string::npos) << r.output;
  const std::string txt = dir_.file("off.txt");
  r = run("convert '" + bag + "' '" + txt + "' --polarity off -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(txt);
  int lines = 0;
  for (std::string line; std::getline(in, line);) {
    ++lines;
    EXPECT_EQ(line.back(), '0') << line;  // RPG text: p 0 = OFF
  }
  EXPECT_EQ(lines, 50);
  const std::string out = dir_.file("p.csv");
  r = run("process '" + csv() + "' --sensor 16x16 --from 0.002 --to 0.005 -q -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream rows(out);
  int n = 0;
  for (std::string line; std::getline(rows, line);) ++n;
  EXPECT_EQ(n, 1 + 3);  // header + x = 2, 3, 4
  EXPECT_EQ(run("eval '" + csv() + "' --polarity sideways -o '" + dir_.file("e") + "'").exit_code, 2);
  EXPECT_EQ(run("run --source 'file:" + csv() + "' --from 5ms --to 1ms").exit_code, 2);
  // An empty range is refused, --to 0 too (from the first event to it: nothing;
  // it read no event and exited 0).
  for (const std::string range : {"--from 2ms --to 2ms", "--to 0", "--to 0us"}) {
    r = run("process '" + csv() + "' --sensor 16x16 " + range + " -q -o '" + dir_.file("e.csv") + "'");
    EXPECT_EQ(r.exit_code, 2) << range << ": " << r.output;
    EXPECT_NE(r.output.find("--to must be after --from"), std::string::npos) << range << ": " << r.output;
  }
  EXPECT_EQ(run("render '" + csv() + "' --polarity up -o '" + dir_.file("r") + "'").exit_code, 2);
}

}  // namespace
