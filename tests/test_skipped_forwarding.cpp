// Records a reader skips (frames, IMU samples, triggers, ...) are never lost
// on the way to the user: every reader that wraps another (the read-ahead
// thread of a paced replay, the checked and cropping readers) passes on the
// counts per kind and the triggers, and `evlife run` shows the same counts as
// `evlife process` for the same file, paced or not.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "davis_aedat2_writer.h"
#include "evlife/engine/prefetch_reader.h"
#include "evlife/io/event_reader.h"
#include "scratch_dir.h"

namespace {

using evlife::Event;
using evlife::SensorSize;
namespace io = evlife::io;

// A reader that skips records of two kinds as it goes: after its k-th read,
// k "frame" records and k / 2 "trigger" records (the triggers also counted
// as triggers), so the counts change from block to block.
class KindsReader final : public io::EventReader {
 public:
  explicit KindsReader(std::size_t n) {
    for (std::size_t i = 0; i < n; ++i)
      events_.push_back(Event{static_cast<std::int64_t>(i), static_cast<std::uint16_t>(i % 7), 3, 1});
  }
  std::size_t read(std::span<Event> out) override {
    const std::size_t n = std::min({out.size(), events_.size() - pos_, std::size_t{333}});
    std::copy_n(events_.begin() + static_cast<std::ptrdiff_t>(pos_), n, out.begin());
    pos_ += n;
    if (n > 0) ++reads_;
    return n;
  }
  std::optional<SensorSize> sensor_size() const override { return SensorSize{8, 8}; }
  std::string_view format_name() const override { return "kinds"; }
  const std::string& path() const override { return path_; }
  std::uint64_t skipped_record_count() const override { return reads_ + reads_ / 2; }
  std::uint64_t trigger_count() const override { return reads_ / 2; }
  std::vector<io::SkippedKindCount> skipped_record_kinds() const override {
    std::vector<io::SkippedKindCount> kinds{{"frame", reads_}};
    if (reads_ / 2 > 0) kinds.push_back({"trigger", reads_ / 2});
    return kinds;
  }
  std::vector<io::ContainerStream> streams() const override { return {{"/events", "kinds/Packet", 9, true}}; }

 private:
  std::vector<Event> events_;
  std::size_t pos_ = 0;
  std::uint64_t reads_ = 0;
  std::string path_ = "kinds.bin";
};

std::string text(const std::vector<io::SkippedKindCount>& kinds) {
  std::string s;
  for (const auto& k : kinds) s += std::string(k.kind) + "=" + std::to_string(k.count) + " ";
  return s;
}

TEST(SkippedForwarding, PrefetchReaderPassesOnEveryCountAsOfTheEventsReturned) {
  const std::size_t n = 10'000;  // 31 inner reads of <= 333 events
  evlife::engine::PrefetchReader reader(std::make_unique<KindsReader>(n), 1000, 3);
  EXPECT_EQ(reader.skipped_record_count(), 0u);
  EXPECT_TRUE(reader.skipped_record_kinds().empty());
  ASSERT_EQ(reader.streams().size(), 1u);
  EXPECT_EQ(reader.streams()[0].name, "/events");
  std::vector<Event> buf(100);
  std::size_t total = 0;
  while (const std::size_t got = reader.read(buf)) {
    total += got;
    // Never ahead of the events handed out: a block's counts arrive with it.
    const std::uint64_t frames = reader.skipped_record_kinds().empty() ? 0 : reader.skipped_record_kinds()[0].count;
    EXPECT_EQ(frames, (total + 332) / 333) << total;  // one inner read (333 events) per block
  }
  EXPECT_EQ(total, n);
  KindsReader whole(n);
  std::vector<Event> all(n);
  while (whole.read(all) > 0) {
  }
  EXPECT_EQ(reader.skipped_record_count(), whole.skipped_record_count());
  EXPECT_EQ(reader.trigger_count(), whole.trigger_count());
  EXPECT_EQ(text(reader.skipped_record_kinds()), text(whole.skipped_record_kinds()));
  EXPECT_EQ(text(reader.skipped_record_kinds()), "frame=31 trigger=15 ");
}

class SkippedForwardingCli : public ::testing::Test {
 protected:
  evlife::test::CliRun run(const std::string& args) const {
    return evlife::test::run_cli(EVLIFE_CLI_PATH, args, dir_.path() / "cli.log");
  }
  const evlife::test::ScratchDir dir_{"test_skipped_forwarding"};
};

// The "... (non-event records of the format: KINDS)" part of a summary line
// that starts with `label`, or "" when there is none.
std::string skipped_line(const std::string& output, const std::string& label) {
  const std::size_t at = output.find(label);
  if (at == std::string::npos) return "";
  const std::size_t open = output.find('(', at);
  const std::size_t end = output.find('\n', at);
  return open < end ? output.substr(open, end - open) : "";
}

TEST_F(SkippedForwardingCli, RunShowsTheSkippedKindsAsProcessDoesPacedOrNot) {
  // A DAVIS240C recording of 0.2 s: DVS events with APS samples, IMU samples
  // and external-input triggers between them.
  evlife::test::DavisAedat2Writer f("eu.seebetter.ini.chips.davis.DAVIS240C", 240, 180);
  for (std::uint32_t t = 0; t < 200'000; t += 500) {
    f.dvs(static_cast<int>(t / 500) % 240, 17, (t / 500) % 2 == 0, t);
    if (t % 10'000 == 0) f.aps(3, 4, 0, 100, t + 1);
    if (t % 20'000 == 0) f.imu({1, 2, 3, 4, 5, 6, 7}, t + 2);
    if (t % 50'000 == 0) f.external(t + 3);
  }
  const std::string file = dir_.save("davis.aedat", f.bytes());
  const auto process = run("process '" + file + "' -o '" + (dir_.path() / "out.csv").string() + "'");
  ASSERT_EQ(process.exit_code, 0) << process.output;
  const std::string expected = skipped_line(process.output, "skipped records");
  // 20 APS samples, 10 IMU samples of 7 words, 4 triggers.
  EXPECT_EQ(expected, "(non-event records of the format: external 4, aps-sample 20, imu-word 70)")
      << process.output;
  EXPECT_NE(process.output.find("skipped records     94 "), std::string::npos) << process.output;
  for (const std::string pacing : {"", " --realtime=4"}) {  // paced: read ahead by PrefetchReader
    const auto r = run("run '" + file + "'" + pacing);
    ASSERT_EQ(r.exit_code, 0) << pacing << "\n" << r.output;
    EXPECT_EQ(skipped_line(r.output, "skipped: "), expected) << pacing << "\n" << r.output;
    EXPECT_NE(r.output.find("skipped: 94 records"), std::string::npos) << pacing << "\n" << r.output;
  }
}

TEST_F(SkippedForwardingCli, CroppedReadsStillCountTheWholeFileReadSoFar) {
  // --from/--to wrap the reader (cropping): its counts pass through as well.
  evlife::test::DavisAedat2Writer f("eu.seebetter.ini.chips.davis.DAVIS240C", 240, 180);
  for (std::uint32_t t = 0; t < 10'000; t += 100) {
    f.dvs(5, 6, true, t);
    f.external(t + 1);
  }
  const std::string file = dir_.save("cropped.aedat", f.bytes());
  io::ReaderOptions options;
  options.polarity = io::PolarityFilter::off;  // no event passes: every record is read
  auto reader = io::open_event_reader(file, options);
  std::vector<Event> buf(64);
  while (reader->read(buf) > 0) {
  }
  EXPECT_EQ(reader->trigger_count(), 100u);
  EXPECT_EQ(text(reader->skipped_record_kinds()), "external=100 ");
}

}  // namespace
