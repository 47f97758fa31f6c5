// AEDAT 2.0 from DAVIS cameras (jAER): files written by a test-only writer
// that packs addresses as jAER's USB code does (tests/support/
// davis_aedat2_writer.h): DVS events of DAVIS240C and DAVIS346 files decode
// to the events written, APS samples, IMU words and external events are
// skipped and counted per kind, the AEChip line sets the sensor, and bad
// input (truncation, corrupt addresses, unknown chips) fails clearly after
// the events before it.
#include <gtest/gtest.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "davis_aedat2_writer.h"
#include "evlife/io/event_reader.h"
#include "evlife/io/sensor_size_from_data.h"
#include "read_all.h"
#include "scratch_dir.h"

namespace {

using evlife::Event;
using evlife::test::DavisAedat2Writer;
namespace io = evlife::io;

using evlife::test::ReadAll;

ReadAll read_all(const std::string& path, std::size_t batch_size = 3) {
  return evlife::test::read_all(path, {}, batch_size);
}

void expect_events(const std::vector<Event>& got, const std::vector<Event>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(got[i].t_us, want[i].t_us) << i;
    EXPECT_EQ(got[i].x, want[i].x) << i;
    EXPECT_EQ(got[i].y, want[i].y) << i;
    EXPECT_EQ(got[i].p, want[i].p) << i;
  }
}

std::string kinds_text(const std::vector<io::SkippedKindCount>& kinds) {
  std::string s;
  for (const auto& k : kinds) s += std::string(k.kind) + "=" + std::to_string(k.count) + " ";
  return s;
}

class IoAedat2Davis : public ::testing::Test {
 protected:
  std::string save(const std::string& name, const std::vector<char>& bytes) const { return dir_.save(name, bytes); }
  evlife::test::ScratchDir dir_{"test_aedat2_davis"};
};

// Every kind of record, DVS events at the corners of the sensor between them.
DavisAedat2Writer mixed(const std::string& chip, int w, int h) {
  DavisAedat2Writer f(chip, w, h);
  f.dvs(0, 0, true, 10);
  f.aps(0, 0, 0, 512, 11);  // reset read
  f.aps(w - 1, h - 1, 1, 1023, 12);  // signal read
  f.dvs(w - 1, h - 1, false, 20);
  f.imu({-100, 200, 8192, 340, 1, -1, 32767}, 25);
  f.external(30);
  f.dvs(5, h - 7, true, 40);
  f.dvs(w - 3, 2, false, 41);
  return f;
}

std::vector<Event> mixed_events(int w, int h) {
  const auto u = [](int v) { return static_cast<std::uint16_t>(v); };
  return {{10, 0, 0, 1}, {20, u(w - 1), u(h - 1), -1}, {40, 5, u(h - 7), 1}, {41, u(w - 3), 2, -1}};
}

TEST_F(IoAedat2Davis, Davis240cAndDavis346DecodeTheDvsEventsAndCountTheRestPerKind) {
  struct Chip {
    std::string aechip;
    int w, h;
  };
  for (const Chip& c : {Chip{"eu.seebetter.ini.chips.davis.DAVIS240C", 240, 180},
                        Chip{"eu.seebetter.ini.chips.davis.Davis346B", 346, 260}}) {
    SCOPED_TRACE(c.aechip);
    for (const std::size_t batch : {std::size_t{1}, std::size_t{3}, std::size_t{4096}}) {
      const ReadAll r = read_all(save("mixed.aedat", mixed(c.aechip, c.w, c.h).bytes()), batch);
      ASSERT_FALSE(r.error) << r.error->what();
      ASSERT_TRUE(r.sensor);
      EXPECT_EQ(r.sensor->width, c.w);
      EXPECT_EQ(r.sensor->height, c.h);
      expect_events(r.events, mixed_events(c.w, c.h));
      EXPECT_EQ(r.skipped, 2u + 7u + 1u);
      EXPECT_EQ(r.triggers, 1u);
      EXPECT_EQ(kinds_text(r.kinds), "external=1 aps-sample=2 imu-word=7 ");
    }
  }
}

TEST_F(IoAedat2Davis, AnAddressPackedByHandDecodesAsJaerShowsItFlippedToTopLeft) {
  // DAVIS240C, raw y 100 (bits 22-30), raw x 200 (bits 12-21), bit 11 ON:
  // 100 << 22 = 0x19000000, 200 << 12 = 0x000C8000, 1 << 11 = 0x800.
  // jAER shows x = 239 - 200 = 39 and y = 100 counted from the bottom, i.e.
  // row 179 - 100 = 79 from the top.
  DavisAedat2Writer f("eu.seebetter.ini.chips.davis.DAVIS240C", 240, 180);
  f.raw(0x190C8800u, 5);
  f.raw(0x190C8000u, 6);  // the same pixel, OFF
  const ReadAll r = read_all(save("hand.aedat", f.bytes()));
  ASSERT_FALSE(r.error) << r.error->what();
  expect_events(r.events, {{5, 39, 79, 1}, {6, 39, 79, -1}});
}

TEST_F(IoAedat2Davis, TheChipTableSetsTheSensor) {
  struct Case {
    std::string aechip;
    int w, h;
  };
  for (const Case& c : {Case{"eu.seebetter.ini.chips.davis.DAVIS240A", 240, 180},
                        Case{"eu.seebetter.ini.chips.DAViS.DAViS240", 240, 180},
                        Case{"eu.seebetter.ini.chips.davis.Davis346cBSI", 346, 260},
                        Case{"eu.seebetter.ini.chips.davis.Davis128", 128, 128},
                        Case{"eu.seebetter.ini.chips.davis.Davis640", 640, 480}}) {
    DavisAedat2Writer f(c.aechip, c.w, c.h);
    f.dvs(c.w - 1, 0, true, 1);
    const ReadAll r = read_all(save("chip.aedat", f.bytes()));
    ASSERT_FALSE(r.error) << c.aechip << ": " << r.error->what();
    ASSERT_TRUE(r.sensor) << c.aechip;
    EXPECT_EQ(r.sensor->width, c.w) << c.aechip;
    EXPECT_EQ(r.sensor->height, c.h) << c.aechip;
    expect_events(r.events, {{1, static_cast<std::uint16_t>(c.w - 1), 0, 1}});
  }
}

// v2e's AEDAT 2.0 writer (v2ecore/output/aedat2_output.py): its own header
// lines and no AEChip line, then big-endian (address, t µs) with the DAVIS
// layout for 346 x 260 or 240 x 180 outputs, both axes flipped:
// address = (W-1-x) << 12 | (H-1-y) << 22 | p << 11 (p 1 = ON).
std::vector<char> v2e_file(int w, int h, const std::vector<Event>& events) {
  const std::string header =
      "#!AER-DAT2.0\r\n"
      "# This is a raw AE data file created by AEDat2Output in v2e (see https://github.com/SensorsINI/v2e) as "
      "specified at https://inivation.com/support/software/fileformat/#aedat-20\r\n"
      "# Data format is int32 address, int32 timestamp (8 bytes total), repeated for each event\r\n"
      "# Timestamps tick is 1 us\r\n"
      "# Creation time: 01:02PM November 29 2026\r\n"
      "# Creation time: System.currentTimeMillis() 1795944856591\r\n"
      "# User name: tester\r\n";
  std::vector<char> bytes(header.begin(), header.end());
  for (const Event& e : events) {
    const auto address = static_cast<std::uint32_t>(((w - 1 - e.x) << 12) | ((h - 1 - e.y) << 22) |
                                                    ((e.p > 0 ? 1 : 0) << 11));
    for (const std::uint32_t v : {address, static_cast<std::uint32_t>(e.t_us)})
      for (int shift = 24; shift >= 0; shift -= 8) bytes.push_back(static_cast<char>((v >> shift) & 0xFF));
  }
  return bytes;
}

TEST_F(IoAedat2Davis, V2eFilesReadAsTheDavisTheyWereWrittenFor) {
  // A DAVIS346 output: its events reach beyond 240 x 180 raw pixels.
  const std::vector<Event> on346 = {{1000, 0, 0, 1}, {1001, 345, 259, -1}, {1002, 100, 200, 1}, {1003, 340, 5, -1}};
  ReadAll r = read_all(save("v2e346.aedat", v2e_file(346, 260, on346)));
  ASSERT_FALSE(r.error) << r.error->what();
  ASSERT_TRUE(r.sensor);
  EXPECT_EQ(r.sensor->width, 346);
  EXPECT_EQ(r.sensor->height, 260);
  expect_events(r.events, on346);
  // A DAVIS240 output.
  const std::vector<Event> on240 = {{5, 0, 0, -1}, {6, 239, 179, 1}, {7, 120, 33, 1}};
  r = read_all(save("v2e240.aedat", v2e_file(240, 180, on240)));
  ASSERT_FALSE(r.error) << r.error->what();
  ASSERT_TRUE(r.sensor);
  EXPECT_EQ(r.sensor->width, 240);
  EXPECT_EQ(r.sensor->height, 180);
  expect_events(r.events, on240);
  // The file names no sensor: the reader says its size is a guess (it said
  // "stated by the file"), as `info` and `process` print it.
  const auto reader = io::open_unchecked_event_reader(save("v2e240.aedat", v2e_file(240, 180, on240)));
  EXPECT_NE(reader->sensor_size_note().find("guessed: v2e names no sensor"), std::string::npos);
  EXPECT_EQ(io::open_unchecked_event_reader(save("chip.aedat", mixed("eu.seebetter.ini.chips.davis.DAVIS240C", 240, 180).bytes()))
                ->sensor_size_note(),
            "");  // an AEChip line states it
  // A DAVIS346 recording whose events all lie within raw 240 x 180: the file
  // cannot tell, the guess (a DAVIS240) shifts it, the user's sensor decides.
  const std::vector<Event> inner346 = {{10, 200, 100, 1}, {20, 300, 200, -1}};
  const std::string inner = save("v2e346_inner.aedat", v2e_file(346, 260, inner346));
  EXPECT_EQ(read_all(inner).sensor->width, 240);
  io::ReaderOptions as346;
  as346.sensor = evlife::SensorSize{346, 260};
  r = evlife::test::read_all(inner, as346, 3);
  ASSERT_FALSE(r.error) << r.error->what();
  expect_events(r.events, inner346);
  EXPECT_EQ(io::resolve_sensor_size(inner, evlife::SensorSize{346, 260}).size, (evlife::SensorSize{346, 260}));
  EXPECT_EQ(io::resolve_sensor_size(inner, std::nullopt).size, (evlife::SensorSize{240, 180}));
}

TEST_F(IoAedat2Davis, TruncationKeepsTheEventsBeforeAndNamesFileAndOffset) {
  DavisAedat2Writer f = mixed("eu.seebetter.ini.chips.davis.DAVIS240C", 240, 180);
  std::vector<char> bytes = f.bytes();
  const std::size_t cut_record = bytes.size() - 8;  // the last DVS event
  bytes.resize(bytes.size() - 3);
  const std::string path = save("cut.aedat", bytes);
  const ReadAll r = read_all(path);
  ASSERT_TRUE(r.error);
  expect_events(r.events, {{10, 0, 0, 1}, {20, 239, 179, -1}, {40, 5, 173, 1}});
  const std::string what = r.error->what();
  EXPECT_NE(what.find("truncated AEDAT 2.0"), std::string::npos) << what;
  EXPECT_NE(what.find(path), std::string::npos) << what;
  EXPECT_EQ(r.error->byte_offset(), static_cast<std::int64_t>(cut_record));
  EXPECT_EQ(r.error->event_index(), 3);
}

TEST_F(IoAedat2Davis, CorruptDvsAddressesFailAfterTheEventsBefore) {
  for (const std::uint32_t bad : {std::uint32_t{240} << 12,          // raw x outside a DAVIS240
                                  std::uint32_t{180} << 22,          // raw y outside
                                  (std::uint32_t{3} << 12) | 0x5u}) {  // bits 0-9 set in a DVS event
    DavisAedat2Writer f("eu.seebetter.ini.chips.davis.DAVIS240C", 240, 180);
    f.dvs(1, 2, true, 7);
    f.imu({1, 2, 3, 4, 5, 6, 7}, 8);
    const std::size_t at = f.size();
    f.raw(bad, 9);
    f.dvs(3, 4, true, 10);
    const std::string path = save("bad.aedat", f.bytes());
    const ReadAll r = read_all(path);
    ASSERT_TRUE(r.error) << std::hex << bad;
    expect_events(r.events, {{7, 1, 2, 1}});
    EXPECT_NE(std::string(r.error->what()).find("corrupt AEDAT 2.0 record"), std::string::npos) << r.error->what();
    EXPECT_EQ(r.error->byte_offset(), static_cast<std::int64_t>(at)) << r.error->what();
  }
}

TEST_F(IoAedat2Davis, ByteOffsetOfAnEventCountsTheSkippedRecordsBeforeIt) {
  DavisAedat2Writer f("eu.seebetter.ini.chips.davis.Davis346B", 346, 260);
  const std::size_t first = f.size();
  f.dvs(1, 1, true, 1);
  f.imu({0, 0, 0, 0, 0, 0, 0}, 2);
  f.aps(3, 3, 0, 9, 3);
  const std::size_t third = f.size() + 16;  // after this event and the external one
  f.dvs(2, 2, true, 4);
  f.external(5);
  f.dvs(3, 3, false, 6);
  const auto reader = io::open_unchecked_event_reader(save("offsets.aedat", f.bytes()));
  std::vector<Event> batch(16);
  ASSERT_EQ(reader->read(batch), 3u);
  EXPECT_EQ(reader->byte_offset_of_event(0), static_cast<std::int64_t>(first));
  EXPECT_EQ(reader->byte_offset_of_event(1), static_cast<std::int64_t>(first + 8 * 9));
  EXPECT_EQ(reader->byte_offset_of_event(2), static_cast<std::int64_t>(third));
}

TEST_F(IoAedat2Davis, UnknownChipAndDavisWithoutChipLineAreRefusedClearly) {
  DavisAedat2Writer unknown("eu.seebetter.ini.chips.davis.CDAVIS", 320, 240);
  try {
    io::open_event_reader(save("cdavis.aedat", unknown.bytes()));
    ADD_FAILURE() << "CDAVIS accepted";
  } catch (const io::ReadError& e) {
    EXPECT_NE(std::string(e.what()).find("CDAVIS"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("Davis346* (346x260)"), std::string::npos) << e.what();
  }
  DavisAedat2Writer no_chip("", 240, 180);
  try {
    io::open_event_reader(save("nochip.aedat", no_chip.bytes()));
    ADD_FAILURE() << "DAVIS file without AEChip line accepted";
  } catch (const io::ReadError& e) {
    EXPECT_NE(std::string(e.what()).find("AEChip"), std::string::npos) << e.what();
  }
}

TEST_F(IoAedat2Davis, InfoShowsTheSensorTriggersAndSkippedKinds) {
  const std::string path = save("info.aedat", mixed("eu.seebetter.ini.chips.davis.DAVIS240C", 240, 180).bytes());
  const auto r = evlife::test::run_cli(EVLIFE_CLI_PATH, "info '" + path + "'", dir_.path() / "cli.log");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("sensor     240x180 (stated by the file)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("events     4 (2 ON, 2 OFF)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("triggers   1\n"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("by kind  external 1, aps-sample 2, imu-word 7\n"), std::string::npos) << r.output;
}

}  // namespace
