// AEDAT 3.1 (cAER): files written here by a test-only writer following the
// format description (no public sample was small enough to share): polarity
// packets with the timestamp overflow, invalid events, frame / IMU / special
// packets skipped and counted, truncation.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "evlife/io/event_reader.h"
#include "read_all.h"
#include "scratch_dir.h"

namespace {

using evlife::Event;
namespace io = evlife::io;

class Aedat3Writer {
 public:
  Aedat3Writer() {
    const std::string header = "#!AER-DAT3.1\r\n#Format: RAW\r\n#Source 1: DAVIS346\r\n#!END-HEADER\r\n";
    bytes_.assign(header.begin(), header.end());
  }
  struct Polarity {
    std::uint32_t x, y;
    bool on;
    std::int32_t ts;
    bool valid = true;
  };
  void polarity(std::int32_t overflow, const std::vector<Polarity>& events, std::int16_t source = 1) {
    packet(1, 8, overflow, static_cast<std::int32_t>(events.size()), source);
    for (const Polarity& e : events) {
      put<std::uint32_t>((e.x << 17) | (e.y << 2) | (e.on ? 2u : 0u) | (e.valid ? 1u : 0u));
      put<std::int32_t>(e.ts);
    }
  }
  struct Special {
    std::uint32_t type;  // libcaer's special event type (bits 1-7)
    bool valid = true;
  };
  /// A special packet (type 0): libcaer's caer_special_event layout.
  void special(const std::vector<Special>& events) {
    packet(0, 8, 0, static_cast<std::int32_t>(events.size()));
    std::int32_t ts = 1000;
    for (const Special& e : events) {
      put<std::uint32_t>((0xABCDu << 8) | (e.type << 1) | (e.valid ? 1u : 0u));
      put<std::int32_t>(ts++);
    }
  }
  /// A packet of another type with `n` events of `size` zero bytes.
  void other(std::int16_t type, std::int32_t size, std::int32_t n) {
    packet(type, size, 0, n);
    bytes_.insert(bytes_.end(), static_cast<std::size_t>(size) * static_cast<std::size_t>(n), '\0');
  }
  const std::vector<char>& bytes() const { return bytes_; }

 private:
  template <typename T>
  void put(T v) {
    const char* p = reinterpret_cast<const char*>(&v);
    bytes_.insert(bytes_.end(), p, p + sizeof(T));
  }
  void packet(std::int16_t type, std::int32_t size, std::int32_t overflow, std::int32_t n, std::int16_t source = 1) {
    put<std::int16_t>(type);
    put<std::int16_t>(source);
    put<std::int32_t>(size);
    put<std::int32_t>(4);  // timestamp offset inside the event
    put<std::int32_t>(overflow);
    put<std::int32_t>(n);  // capacity
    put<std::int32_t>(n);  // number
    put<std::int32_t>(n);  // valid
  }
  std::vector<char> bytes_;
};

class IoAedat3 : public ::testing::Test {
 protected:
  std::string save(const std::string& name, const std::vector<char>& bytes) const { return dir_.save(name, bytes); }
  evlife::test::ScratchDir dir_{"test_io_aedat3"};
};

using evlife::test::ReadAll;

ReadAll read_all(const std::string& path) { return evlife::test::read_all(path, {}, 2); }

// "kind=count " for every kind seen.
std::string kinds_text(const ReadAll& r) {
  std::string text;
  for (const io::SkippedKindCount& k : r.kinds) text += std::string(k.kind) + "=" + std::to_string(k.count) + " ";
  return text;
}

Aedat3Writer sample() {
  Aedat3Writer w;
  w.polarity(0, {{10, 20, true, 100}, {11, 21, false, 200, false}, {345, 259, false, 2'147'483'000}});
  w.other(3, 36, 2);    // IMU6
  w.other(2, 64, 1);    // a (tiny) frame
  w.special({{0}});     // a timestamp wrap marker
  w.polarity(1, {{1, 2, true, 5}});  // after the 31-bit overflow
  return w;
}

TEST_F(IoAedat3, PolarityPacketsWithOverflowOthersSkippedAndCounted) {
  const ReadAll r = read_all(save("a.aedat", sample().bytes()));
  ASSERT_FALSE(r.error) << r.error->what();
  EXPECT_EQ(r.format, "aedat3");
  const std::vector<Event> expected = {
      {100, 10, 20, 1}, {2'147'483'000, 345, 259, -1}, {(std::int64_t{1} << 31) + 5, 1, 2, 1}};
  ASSERT_EQ(r.events.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(r.events[i].t_us, expected[i].t_us) << i;
    EXPECT_EQ(r.events[i].x, expected[i].x) << i;
    EXPECT_EQ(r.events[i].y, expected[i].y) << i;
    EXPECT_EQ(r.events[i].p, expected[i].p) << i;
  }
  EXPECT_EQ(r.skipped, 1u + 2u + 1u + 1u);  // invalid event, 2 IMU, 1 frame, 1 special
  // Per kind, in the order of the specification's type ids (evlife's own last).
  EXPECT_EQ(kinds_text(r), "special=1 frame=1 imu6=2 polarity-invalid=1 ");
}

// Two cameras of one cAER setup (sources 1 and 2): the second's polarity
// packets were read as the first camera's events (a 301x201 "sensor" of two
// interleaved ones). One camera is read, the other's events are counted.
TEST_F(IoAedat3, PolarityOfASecondSourceIsCountedNotMixedIn) {
  Aedat3Writer w;
  w.polarity(0, {{1, 1, true, 10}, {2, 2, false, 20}}, 2);  // the first polarity packet: source 2
  w.polarity(0, {{300, 200, true, 30}, {5, 5, true, 40}}, 1);
  w.polarity(0, {{3, 3, true, 50}}, 2);
  const ReadAll r = read_all(save("two.aedat", w.bytes()));
  ASSERT_FALSE(r.error) << r.error->what();
  ASSERT_EQ(r.events.size(), 3u);
  EXPECT_EQ(r.events[0].t_us, 10);
  EXPECT_EQ(r.events[1].t_us, 20);
  EXPECT_EQ(r.events[2].t_us, 50);
  EXPECT_EQ(r.skipped, 2u);
  EXPECT_EQ(kinds_text(r), "polarity-other-source=2 ");
}

TEST_F(IoAedat3, ExternalInputSpecialEventsAreTheTriggers) {
  Aedat3Writer w;
  w.polarity(0, {{1, 1, true, 10}});
  // libcaer events/special.h: 2-4 EXTERNAL_INPUT_{RISING_EDGE,FALLING_EDGE,PULSE},
  // 6-8 EXTERNAL_INPUT1_..., 9-11 EXTERNAL_INPUT2_... are triggers; 0 wrap,
  // 1 reset, 5 row only, 12/13 the generator's edges, 14-18 APS/readout are not.
  std::vector<Aedat3Writer::Special> specials;
  for (std::uint32_t type = 0; type <= 18; ++type) specials.push_back({type});
  specials.push_back({2, false});  // no valid mark: neither
  w.special(specials);
  w.polarity(0, {{2, 2, false, 20}});
  w.special({{4}, {4}});
  const ReadAll r = read_all(save("special.aedat", w.bytes()));
  ASSERT_FALSE(r.error) << r.error->what();
  EXPECT_EQ(r.events.size(), 2u);  // never mixed into the events
  EXPECT_EQ(r.triggers, 9u + 2u);
  EXPECT_EQ(kinds_text(r), "special=10 trigger=11 special-invalid=1 ");
  EXPECT_EQ(r.skipped, 22u);
}

TEST_F(IoAedat3, SpecialPacketFaultsKeepTheEventsBefore) {
  Aedat3Writer w;
  w.polarity(0, {{1, 1, true, 10}});
  w.special({{2}, {3}});
  std::vector<char> cut = w.bytes();
  cut.resize(cut.size() - 5);  // inside the second special event
  ReadAll r = read_all(save("cut_special.aedat", cut));
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.triggers, 1u);
  EXPECT_NE(std::string(r.error->what()).find("truncated AEDAT 3.1 special packet"), std::string::npos)
      << r.error->what();
  Aedat3Writer bad;
  bad.polarity(0, {{1, 1, true, 10}});
  bad.other(0, 12, 1);  // special events are 8 bytes
  r = read_all(save("wide_special.aedat", bad.bytes()));
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.events.size(), 1u);
  EXPECT_NE(std::string(r.error->what()).find("special packet with 12-byte events"), std::string::npos)
      << r.error->what();
}

TEST_F(IoAedat3, EveryOtherPacketTypeIsCountedUnderItsName) {
  Aedat3Writer w;
  const std::int16_t types[] = {4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 99};
  std::int32_t n = 1;
  for (const std::int16_t type : types) w.other(type, 8, n++);  // (the timestamp at 4 inside each)
  const ReadAll r = read_all(save("kinds.aedat", w.bytes()));
  ASSERT_FALSE(r.error) << r.error->what();
  EXPECT_TRUE(r.events.empty());
  EXPECT_EQ(kinds_text(r),
            "imu9=1 sample=2 ear=3 config=4 point1d=5 point2d=6 point3d=7 point4d=8 spike=9 matrix4x4=10 "
            "unknown-type=11 ");
  EXPECT_EQ(r.skipped, 66u);
}

// Bytes lost inside a packet (a shift): the next header is read from the
// wrong offset. Such a header was skipped as a packet of another type
// ("point1d"), and the events after it were lost or kept by chance, exit 0.
// Its fields rarely hold what every libcaer header holds: an input error.
TEST_F(IoAedat3, AHeaderReadFromTheWrongOffsetIsAFault) {
  const std::vector<char> whole = sample().bytes();
  const std::size_t first_packet = whole.size() - (28 + 8) - (28 + 8) - (28 + 64) - (28 + 72) - (28 + 24);
  const std::size_t imu = first_packet + 28 + 24;
  const std::size_t special = imu + 28 + 72 + 28 + 64;
  ASSERT_EQ(whole[imu], 3);      // the IMU6 packet's type
  ASSERT_EQ(whole[special], 0);  // the special packet's type
  for (const auto& [at, lost] : std::vector<std::pair<std::size_t, std::size_t>>{
           {imu + 28 + 30, 4},       // inside the IMU samples
           {special + 19, 8},        // inside the special packet's header
           {special + 28 + 3, 4}}) {  // inside its event, before the last polarity packet
    std::vector<char> bytes = whole;
    bytes.erase(bytes.begin() + static_cast<std::ptrdiff_t>(at), bytes.begin() + static_cast<std::ptrdiff_t>(at + lost));
    const ReadAll r = read_all(save("shifted.aedat", bytes));
    ASSERT_TRUE(r.error) << lost << " bytes lost at " << at << ": " << r.events.size() << " events, " << kinds_text(r);
    EXPECT_EQ(r.events.size(), 2u) << at;  // the first packet's
    EXPECT_NE(std::string(r.error->what()).find("corrupt AEDAT 3.1 packet header"), std::string::npos)
        << r.error->what();
  }
}

TEST_F(IoAedat3, TruncatedPacketKeepsTheEventsBefore) {
  std::vector<char> bytes = sample().bytes();
  bytes.resize(bytes.size() - 3);  // inside the last polarity event
  const std::string path = save("cut.aedat", bytes);
  const ReadAll r = read_all(path);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.events.size(), 2u);
  EXPECT_NE(std::string(r.error->what()).find("truncated AEDAT 3.1"), std::string::npos) << r.error->what();
  EXPECT_EQ(r.error->byte_offset(), static_cast<std::int64_t>(bytes.size() + 3 - 8));
}

}  // namespace
