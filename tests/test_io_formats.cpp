// Readers of today's camera formats (AEDAT 4.0, Prophesee EVT 2.0 / 3.0 /
// DAT) on the real samples in ../shared/data. Expected values come from
// PROVENANCE.md (counts) and from an independent Python decode written from
// the format descriptions (first/last events, coordinate sums); the DAT
// sample is compared event by event with the NumPy array shipped beside it.
// AEDAT 4.0 files built here byte by byte cover the uncompressed and Zstd
// variants. Truncated and bit-flipped copies must end in a clean ReadError.
#include <gtest/gtest.h>
#include <zstd.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "decimal_number.h"
#include "evlife/io/event_reader.h"
#include "evt21_reader.h"
#include "scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using evlife::Event;
using evlife::SensorSize;
using evlife::io::ReadError;
using evlife::test::ScratchDir;

const std::string kData = EVLIFE_SHARED_DATA_DIR;
const std::string kAedat4 = kData + "/aedat4/sample.aedat4";
const std::string kEvt2 = kData + "/evt2/evt2_sample.raw";
const std::string kEvt3 = kData + "/evt3/evt3_sample.raw";
const std::string kDat = kData + "/prophesee_dat/NCARS_obj_004397_td.dat";
const std::string kDatNpy = kData + "/prophesee_dat/NCARS_obj_004397_td.groundtruth.npy";

struct ReadResult {
  std::vector<Event> events;
  std::optional<ReadError> error;
  std::uint64_t skipped = 0;
  std::optional<SensorSize> sensor;
  std::string format;
};

// Reads the whole file (decoder alone unless `checked`), `buffer` events per call.
ReadResult read_all(const std::string& path, std::size_t buffer = 4096, bool checked = false) {
  ReadResult result;
  try {
    auto reader = checked ? evlife::io::open_event_reader(path)
                          : evlife::io::open_unchecked_event_reader(path);
    result.sensor = reader->sensor_size();
    result.format = std::string(reader->format_name());
    std::vector<Event> chunk(buffer);
    try {
      while (const std::size_t n = reader->read(chunk)) {
        result.events.insert(result.events.end(), chunk.begin(), chunk.begin() + static_cast<std::ptrdiff_t>(n));
      }
    } catch (const ReadError& e) {
      result.error = e;
    }
    result.skipped = reader->skipped_record_count();
  } catch (const ReadError& e) {
    result.error = e;
  }
  return result;
}

std::vector<std::uint8_t> load(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// True if `part` equals the first part.size() events of `full`.
bool is_prefix(const std::vector<Event>& part, const std::vector<Event>& full) {
  if (part.size() > full.size()) return false;
  for (std::size_t i = 0; i < part.size(); ++i) {
    const Event& a = part[i];
    const Event& b = full[i];
    if (a.t_us != b.t_us || a.x != b.x || a.y != b.y || a.p != b.p) return false;
  }
  return true;
}

// Offset of the first byte after the '%' header lines.
std::size_t prophesee_header_end(const std::vector<std::uint8_t>& bytes) {
  std::size_t pos = 0;
  while (pos < bytes.size() && bytes[pos] == '%') {
    while (pos < bytes.size() && bytes[pos] != '\n') ++pos;
    ++pos;
  }
  return pos;
}

struct Expected {
  std::size_t count;
  SensorSize sensor;
  Event first, last;
  std::int64_t sum_x, sum_y;
  std::size_t on_count;
};

void expect_decoded(const ReadResult& r, const Expected& e) {
  ASSERT_FALSE(r.error) << r.error->what();
  ASSERT_EQ(r.events.size(), e.count);
  ASSERT_TRUE(r.sensor.has_value());
  EXPECT_EQ(*r.sensor, e.sensor);
  std::int64_t sum_x = 0, sum_y = 0;
  std::size_t on = 0;
  for (std::size_t i = 0; i < r.events.size(); ++i) {
    const Event& ev = r.events[i];
    ASSERT_TRUE(e.sensor.contains(ev.x, ev.y)) << "event " << i;
    ASSERT_TRUE(ev.p == 1 || ev.p == -1) << "event " << i;
    if (i > 0) {
      ASSERT_LE(r.events[i - 1].t_us, ev.t_us) << "time goes back at event " << i;
    }
    sum_x += ev.x;
    sum_y += ev.y;
    on += ev.p == 1;
  }
  EXPECT_EQ(sum_x, e.sum_x);
  EXPECT_EQ(sum_y, e.sum_y);
  EXPECT_EQ(on, e.on_count);
  const auto same = [](const Event& a, const Event& b) {
    return a.t_us == b.t_us && a.x == b.x && a.y == b.y && a.p == b.p;
  };
  EXPECT_TRUE(same(r.events.front(), e.first));
  EXPECT_TRUE(same(r.events.back(), e.last));
}

// ---- complete decodes of the samples ----

TEST(IoFormatsSamples, Evt2DecodesCompletely) {
  const ReadResult r = read_all(kEvt2, 4096, /*checked=*/true);
  EXPECT_EQ(r.format, "evt2");
  expect_decoded(r, {539'481, {640, 480}, {1'317'888, 237, 121, 1}, {1'367'888, 210, 142, 1},
                     171'811'022, 110'162'026, 367'855});
  EXPECT_EQ(r.skipped, 0u);
}

TEST(IoFormatsSamples, Evt3DecodesCompletely) {
  const ReadResult r = read_all(kEvt3, 4096, /*checked=*/true);
  EXPECT_EQ(r.format, "evt3");
  expect_decoded(r, {219'596, {1280, 720}, {11'718'656, 874, 200, -1}, {11'727'457, 1218, 572, 1},
                     159'113'225, 85'638'051, 115'532});
}

TEST(IoFormatsSamples, Evt3SameEventsWhateverTheBufferSize) {
  // Vector words carry up to 12 events: buffers smaller than that must work.
  const ReadResult reference = read_all(kEvt3, 4096);
  for (const std::size_t buffer : {1u, 5u, 12u, 13u, 100u}) {
    const ReadResult r = read_all(kEvt3, buffer);
    ASSERT_FALSE(r.error);
    ASSERT_EQ(r.events.size(), reference.events.size()) << "buffer " << buffer;
    EXPECT_TRUE(is_prefix(r.events, reference.events)) << "buffer " << buffer;
  }
}

TEST(IoFormatsSamples, Aedat4DecodesCompletely) {
  const ReadResult r = read_all(kAedat4, 4096, /*checked=*/true);
  EXPECT_EQ(r.format, "aedat4");
  expect_decoded(r, {111'954, {320, 240}, {1'605'537'493'718'345, 154, 204, -1},
                     {1'605'537'494'308'262, 88, 237, 1}, 18'342'405, 15'105'898, 55'023});
  EXPECT_EQ(r.skipped, 59u);  // IMU packets
  // Said as packets of their stream's type (they were "59 records", no kind: 59 packets of many samples).
  auto reader = evlife::io::open_event_reader(kAedat4);
  std::vector<Event> all(200'000);
  while (reader->read(all) > 0) {
  }
  EXPECT_EQ(evlife::io::skipped_kinds_text(*reader), "imu-packet 59");
  ASSERT_FALSE(r.events.empty());
  const double duration_s = static_cast<double>(r.events.back().t_us - r.events.front().t_us) * 1e-6;
  EXPECT_NEAR(duration_s, 0.59, 0.01);
}

TEST(IoFormatsSamples, Aedat4SameEventsWhateverTheBufferSize) {
  const ReadResult reference = read_all(kAedat4, 4096);
  const ReadResult r = read_all(kAedat4, 7);
  ASSERT_EQ(r.events.size(), reference.events.size());
  EXPECT_TRUE(is_prefix(r.events, reference.events));
}

// NumPy .npy, structured array (t <i8, x <i2, y <i2, p |u1), packed 13-byte records.
std::vector<Event> load_npy_events(const std::string& path) {
  const std::vector<std::uint8_t> bytes = load(path);
  EXPECT_GE(bytes.size(), 10u);
  EXPECT_EQ(0, std::memcmp(bytes.data(), "\x93NUMPY", 6));
  std::size_t header_end;
  if (bytes[6] == 1) {
    header_end = 10 + (bytes[8] | (bytes[9] << 8));
  } else {
    header_end = 12 + (bytes[8] | (bytes[9] << 8) | (bytes[10] << 16) | (std::size_t{bytes[11]} << 24));
  }
  const std::string header(bytes.begin() + 10, bytes.begin() + static_cast<std::ptrdiff_t>(header_end));
  EXPECT_NE(header.find("('t', '<i8'), ('x', '<i2'), ('y', '<i2'), ('p', '|u1')"), std::string::npos)
      << header;
  EXPECT_NE(header.find("'fortran_order': False"), std::string::npos);
  std::vector<Event> events;
  for (std::size_t at = header_end; at + 13 <= bytes.size(); at += 13) {
    Event e;
    std::int16_t x, y;
    std::memcpy(&e.t_us, &bytes[at], 8);
    std::memcpy(&x, &bytes[at + 8], 2);
    std::memcpy(&y, &bytes[at + 10], 2);
    e.x = static_cast<std::uint16_t>(x);
    e.y = static_cast<std::uint16_t>(y);
    e.p = bytes[at + 12] != 0 ? 1 : -1;
    events.push_back(e);
  }
  EXPECT_EQ((bytes.size() - header_end) % 13, 0u);
  return events;
}

TEST(IoFormatsSamples, DatMatchesTheNumpyDecodeEventByEvent) {
  const std::vector<Event> expected = load_npy_events(kDatNpy);
  ASSERT_EQ(expected.size(), 4'407u);  // PROVENANCE.md
  const ReadResult r = read_all(kDat, 4096, /*checked=*/false);
  ASSERT_FALSE(r.error) << r.error->what();
  EXPECT_EQ(r.format, "prophesee-dat");
  EXPECT_FALSE(r.sensor.has_value());  // the N-CARS header states no geometry
  ASSERT_EQ(r.events.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const Event& a = r.events[i];
    const Event& b = expected[i];
    ASSERT_TRUE(a.t_us == b.t_us && a.x == b.x && a.y == b.y && a.p == b.p)
        << "event " << i << ": got t=" << a.t_us << " x=" << a.x << " y=" << a.y << " p=" << int{a.p}
        << ", numpy t=" << b.t_us << " x=" << b.x << " y=" << b.y << " p=" << int{b.p};
  }
  // The checked reader (time order) accepts it too.
  EXPECT_FALSE(read_all(kDat, 4096, /*checked=*/true).error);
}

// Readers write whole events into buffers that may hold anything (the
// pipeline's are not zeroed): no byte of an event comes from the buffer.
TEST(IoFormatsSharedFiles, EveryReaderWritesWholeEventsIntoAnyBuffer) {
  const ScratchDir dir("test_io_formats");
  const std::string csv = dir.save("junk.csv", std::string("x,y,p,t\n1,2,1,100\n3,4,0,200\n"));
  for (const std::string& path :
       {kAedat4, kEvt2, kEvt3, kDat, kData + "/aedat2/alex_walking_again.aedat", kData + "/reference/stripes.mat",
        kData + "/rpg_txt/slider_depth_events_chunk.txt", csv}) {
    SCOPED_TRACE(path);
    auto reader = evlife::io::open_unchecked_event_reader(path);
    std::vector<Event> chunk(4096);
    std::uint64_t events = 0;
    for (int round = 0; round < 4; ++round) {
      std::memset(static_cast<void*>(chunk.data()), 0xA5, chunk.size() * sizeof(Event));
      const std::size_t n = reader->read(chunk);
      for (std::size_t i = 0; i < n; ++i) {
        ASSERT_TRUE(chunk[i].reserved[0] == 0 && chunk[i].reserved[1] == 0 && chunk[i].reserved[2] == 0)
            << "event " << events + i;
      }
      events += n;
    }
    EXPECT_GT(events, 0u);
  }
}

// ---- time unwrapping and state handling on hand-made word streams ----

template <typename Word>
std::vector<std::uint8_t> with_words(const std::string& header, const std::vector<Word>& words) {
  std::vector<std::uint8_t> bytes(header.begin(), header.end());
  for (const Word w : words) {
    for (std::size_t k = 0; k < sizeof(Word); ++k) bytes.push_back(static_cast<std::uint8_t>(w >> (8 * k)));
  }
  return bytes;
}

TEST(IoFormatsWordStreams, Evt2TimeHighWrapsTo64BitsAndTriggersAreCounted) {
  const ScratchDir dir("test_io_formats");
  const auto cd = [](std::uint32_t type, std::uint32_t t_low, std::uint32_t x, std::uint32_t y) {
    return (type << 28) | (t_low << 22) | (x << 11) | y;
  };
  const std::vector<std::uint32_t> words = {
      0x80000000u | 0x0FFFFFFFu,  // TIME_HIGH = max: t = (2^28 - 1) << 6
      cd(1, 5, 639, 479),
      0xA0000000u,                // EXT_TRIGGER: skipped, counted
      0x80000000u | 0x00000001u,  // TIME_HIGH wraps around
      cd(0, 63, 0, 0),
  };
  const ReadResult r = read_all(dir.save("wrap.raw", with_words("% evt 2.0\n% geometry 640x480\n", words)));
  ASSERT_FALSE(r.error) << r.error->what();
  ASSERT_EQ(r.events.size(), 2u);
  EXPECT_EQ(*r.sensor, (SensorSize{640, 480}));
  EXPECT_EQ(r.events[0].t_us, ((std::int64_t{1} << 28) - 1) * 64 + 5);
  EXPECT_EQ(r.events[1].t_us, (std::int64_t{1} << 34) + 64 + 63);
  EXPECT_TRUE(r.events[0].x == 639 && r.events[0].y == 479 && r.events[0].p == 1);
  EXPECT_TRUE(r.events[1].x == 0 && r.events[1].y == 0 && r.events[1].p == -1);
  EXPECT_EQ(r.skipped, 1u);
}

TEST(IoFormatsWordStreams, Evt3TimeWrapsVectorsAndGeometryFromFormatLine) {
  const ScratchDir dir("test_io_formats");
  const std::vector<std::uint16_t> words = {
      0x8FFF,           // TIME_HIGH = 4095
      0x6ABC,           // TIME_LOW: t = 4095 << 12 | 0xABC
      0x0000 | 7,       // ADDR_Y = 7
      0x3000 | 0x800 | 100,  // VECT_BASE_X = 100, ON
      0x4000 | 0x805,   // VECT_12: bits 0, 2, 11 -> x = 100, 102, 111
      0x5000 | 0x81,    // VECT_8: bits 0, 7 -> x = 112, 119 (base advanced by 12)
      0xA000,           // EXT_TRIGGER
      0x8000,           // TIME_HIGH = 0: wrap of the 24-bit time
      0x6001,           // TIME_LOW = 1
      0x2000 | 1279,    // ADDR_X: x = 1279, OFF
  };
  const ReadResult r = read_all(
      dir.save("wrap3.raw", with_words("% format EVT3;height=720;width=1280\n", words)), 2);
  ASSERT_FALSE(r.error) << r.error->what();
  EXPECT_EQ(*r.sensor, (SensorSize{1280, 720}));
  const std::int64_t t1 = (std::int64_t{4095} << 12) | 0xABC;
  const std::int64_t t2 = (std::int64_t{1} << 24) + 1;
  const std::vector<Event> expected = {{t1, 100, 7, 1}, {t1, 102, 7, 1}, {t1, 111, 7, 1},
                                       {t1, 112, 7, 1}, {t1, 119, 7, 1}, {t2, 1279, 7, -1}};
  ASSERT_EQ(r.events.size(), expected.size());
  EXPECT_TRUE(is_prefix(r.events, expected));
  EXPECT_EQ(r.skipped, 1u);
}

TEST(IoFormatsWordStreams, RawWithoutEvtLineIsKnownByItsCameraPlugin) {
  // Older RAW headers name only the plugin: Gen3 cameras write EVT 2.0 at 640x480.
  const ScratchDir dir("test_io_formats");
  const std::vector<std::uint32_t> words = {0x80000010u, (1u << 28) | (3u << 11) | 4u};
  const ReadResult r = read_all(
      dir.save("old.raw", with_words("% plugin_name hal_plugin_gen3_fx3\n% system_ID 21\n", words)));
  ASSERT_FALSE(r.error) << r.error->what();
  EXPECT_EQ(r.format, "evt2");
  EXPECT_EQ(*r.sensor, (SensorSize{640, 480}));
  ASSERT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.events[0].t_us, 16 * 64);
}

TEST(IoFormatsWordStreams, RawOfAnotherEvtVersionNamesItsVersion) {
  // A RAW version no reader decodes: the error says which version and what to
  // do, not "unknown format".
  const ScratchDir dir("test_io_formats");
  const std::vector<std::uint64_t> words = {std::uint64_t{0x8} << 60, std::uint64_t{0x1} << 60 | 0x5};
  const std::string path = dir.save("future.raw", with_words("% evt 4.0\n% geometry 320x320\n", words));
  const ReadResult r = read_all(path);
  ASSERT_TRUE(r.error);
  const std::string message = r.error->what();
  EXPECT_NE(message.find(path), std::string::npos) << message;
  EXPECT_NE(message.find("Prophesee RAW EVT 4.0"), std::string::npos) << message;
  EXPECT_NE(message.find("EVT 2.0, 2.1 and 3.0 only"), std::string::npos) << message;
  EXPECT_EQ(message.find("unknown event file format"), std::string::npos) << message;
  EXPECT_TRUE(r.events.empty());
}

TEST(IoFormatsWordStreams, MatlabV73FileSaysHowToSaveItAsV5) {
  // MATLAB's save -v7.3 writes HDF5 behind a 512-byte text header.
  const ScratchDir dir("test_io_formats");
  std::string bytes = "MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Mon Nov 30 12:00:00 2026 HDF5 schema 1.00 .";
  bytes.resize(512, ' ');
  bytes += std::string("\x89HDF\r\n\x1a\n", 8) + std::string(64, '\0');
  const std::string path = dir.save("events.mat", bytes);
  const ReadResult r = read_all(path);
  ASSERT_TRUE(r.error);
  const std::string message = r.error->what();
  EXPECT_NE(message.find(path), std::string::npos) << message;
  EXPECT_NE(message.find("MATLAB v7.3"), std::string::npos) << message;
  EXPECT_NE(message.find("'-v7'"), std::string::npos) << message;
  EXPECT_EQ(message.find("unknown event file format"), std::string::npos) << message;
}

// EVT 2.1 words as Prophesee's EVT 2.1 page lays them out (64 bits: type
// 63-60, then t low 59-54, x 53-43, y 42-32, mask 31-0 for events; t >> 6 at
// 59-32 for TIME_HIGH), written in either byte order the page names.
std::uint64_t evt21_event(std::uint64_t type, std::uint64_t t_low, std::uint64_t x, std::uint64_t y,
                          std::uint32_t mask) {
  return (type << 60) | (t_low << 54) | (x << 43) | (y << 32) | mask;
}
std::uint64_t evt21_time_high(std::uint64_t t_high) { return (std::uint64_t{0x8} << 60) | (t_high << 32); }
// IMX636: each word as two little-endian 32-bit halves, the upper half first.
std::vector<std::uint32_t> upper_half_first(const std::vector<std::uint64_t>& words) {
  std::vector<std::uint32_t> halves;
  for (const std::uint64_t w : words) {
    halves.push_back(static_cast<std::uint32_t>(w >> 32));
    halves.push_back(static_cast<std::uint32_t>(w));
  }
  return halves;
}

TEST(IoFormatsWordStreams, Evt21VectorsInEitherByteOrder) {
  const ScratchDir dir("test_io_formats");
  const std::vector<std::uint64_t> words = {
      evt21_time_high(3),                       // t = 3 << 6 = 192
      evt21_event(1, 5, 32, 7, 0b1001),         // ON at x 32 and 35, t 197
      std::uint64_t{0xA} << 60,                 // EXT_TRIGGER: skipped, counted
      evt21_event(0, 63, 288, 319, 1u << 31),   // OFF at x 319, t 255
      evt21_time_high(0x08000000),              // (steps of less than half the range)
      evt21_time_high(0x0FFFFFFF),              // the last TIME_HIGH before the wrap
      evt21_time_high(1),                       // wraps: t = (2^28 + 1) << 6
      evt21_event(1, 0, 0, 0, 0xFFFFFFFFu),     // 32 events, x 0..31
  };
  const std::vector<std::pair<std::string, std::vector<std::uint8_t>>> files = {
      {"genx320.raw", with_words("% format EVT21;height=320;width=320\n", words)},
      {"imx636.raw", with_words("% evt 2.1\n% geometry 320x320\n", upper_half_first(words))},
  };
  for (const auto& [name, bytes] : files) {
    const std::string path = dir.save(name, bytes);
    const ReadResult r = read_all(path, 4096, /*checked=*/true);
    ASSERT_FALSE(r.error) << name << ": " << r.error->what();
    EXPECT_EQ(r.format, "evt21");
    EXPECT_EQ(*r.sensor, (SensorSize{320, 320}));
    ASSERT_EQ(r.events.size(), 35u) << name;
    EXPECT_TRUE(r.events[0].x == 32 && r.events[0].y == 7 && r.events[0].p == 1 && r.events[0].t_us == 197);
    EXPECT_TRUE(r.events[1].x == 35 && r.events[1].y == 7 && r.events[1].p == 1 && r.events[1].t_us == 197);
    EXPECT_TRUE(r.events[2].x == 319 && r.events[2].y == 319 && r.events[2].p == -1 && r.events[2].t_us == 255);
    const std::int64_t wrapped = ((std::int64_t{1} << 28) + 1) * 64;
    for (int k = 0; k < 32; ++k) {
      const Event& e = r.events[3 + static_cast<std::size_t>(k)];
      EXPECT_TRUE(e.x == k && e.y == 0 && e.p == 1 && e.t_us == wrapped) << name << " event " << 3 + k;
    }
    EXPECT_EQ(r.skipped, 1u);
    // Buffers smaller than a word's 32 events give the same events.
    for (const std::size_t buffer : {1u, 7u, 31u, 33u}) {
      const ReadResult small = read_all(path, buffer);
      ASSERT_FALSE(small.error) << name << " buffer " << buffer;
      ASSERT_EQ(small.events.size(), r.events.size()) << name << " buffer " << buffer;
      EXPECT_TRUE(is_prefix(small.events, r.events)) << name << " buffer " << buffer;
    }
  }
}

TEST(IoFormatsWordStreams, Evt21BadWordsStopWithTheirOffset) {
  const ScratchDir dir("test_io_formats");
  const std::string header = "% format EVT21;height=320;width=320\n";
  const std::size_t first_word = header.size();
  // A group whose last pixel lies past the sensor's right edge (x 300 of a
  // 300-wide sensor), and a group that starts there.
  {
    const ReadResult r = read_all(dir.save("outside.raw", with_words("% format EVT21;height=320;width=300\n",
        std::vector<std::uint64_t>{evt21_time_high(1), evt21_event(1, 0, 0, 0, 1),
                                   evt21_event(1, 0, 288, 0, (1u << 12) | 1u)})));
    ASSERT_TRUE(r.error);
    EXPECT_EQ(r.events.size(), 1u);  // the events before the fault are returned
    const std::string message = r.error->what();
    EXPECT_NE(message.find("x=300 y=0 outside the sensor"), std::string::npos) << message;
  }
  {
    const ReadResult r = read_all(dir.save("outside2.raw", with_words(header, std::vector<std::uint64_t>{
        evt21_event(1, 0, 320, 0, 1)})));
    ASSERT_TRUE(r.error);
    EXPECT_NE(std::string(r.error->what()).find("x=320 y=0 outside the sensor"), std::string::npos)
        << r.error->what();
    EXPECT_NE(std::string(r.error->what()).find(std::to_string(first_word)), std::string::npos) << r.error->what();
  }
  // A reserved word type, and a word cut short.
  {
    const ReadResult r = read_all(dir.save("reserved.raw", with_words(header, std::vector<std::uint64_t>{
        evt21_time_high(0), evt21_event(0, 1, 0, 1, 1), std::uint64_t{0x5} << 60})));
    ASSERT_TRUE(r.error);
    EXPECT_EQ(r.events.size(), 1u);
    EXPECT_NE(std::string(r.error->what()).find("unknown EVT 2.1 word type 5"), std::string::npos) << r.error->what();
  }
  {
    std::vector<std::uint8_t> bytes =
        with_words(header, std::vector<std::uint64_t>{evt21_time_high(0), evt21_event(1, 2, 0, 3, 1)});
    bytes.insert(bytes.end(), {1, 2, 3});
    const ReadResult r = read_all(dir.save("cut.raw", bytes));
    ASSERT_TRUE(r.error);
    EXPECT_EQ(r.events.size(), 1u);
    EXPECT_NE(std::string(r.error->what()).find("truncated EVT 2.1 word (3 trailing bytes)"), std::string::npos)
        << r.error->what();
  }
}

// The time base of Prophesee streams, as the specifications and OpenEB's
// decoders have it (found by a spec-driven generator): events before the
// first TIME_HIGH have no time and are skipped and counted (they were stamped
// with TIME_HIGH = 0, as if at the clock's start); in EVT 3.0 a repeated
// TIME_HIGH (sent every 16 us) keeps TIME_LOW's bits (they were cleared: time
// went back), and a drop of exactly half the TIME_HIGH range is a wrap.
TEST(IoFormatsWordStreams, PropheseeTimeBaseFollowsTheSpecification) {
  const ScratchDir dir("test_io_formats");
  {  // EVT 2.0: CD_ON before the first TIME_HIGH, TIME_HIGH 1000, CD_ON
    const ReadResult r = read_all(dir.save("evt2_cut.raw", with_words(
        "% evt 2.0\n% format EVT2;height=480;width=640\n% end\n",
        std::vector<std::uint32_t>{0x11405014u, 0x800003e8u, 0x11c05814u})));
    ASSERT_FALSE(r.error) << r.error->what();
    ASSERT_EQ(r.events.size(), 1u);
    EXPECT_EQ(r.events[0].t_us, 1000 * 64 + 7);
    EXPECT_EQ(r.skipped, 1u);
  }
  {  // EVT 2.1: a group of two pixels before the first TIME_HIGH
    const ReadResult r = read_all(dir.save("evt21_cut.raw", with_words(
        "% format EVT21;height=320;width=320\n",
        std::vector<std::uint64_t>{evt21_event(1, 5, 0, 20, 0b101), evt21_time_high(1000), evt21_event(1, 7, 32, 20, 1)})));
    ASSERT_FALSE(r.error) << r.error->what();
    ASSERT_EQ(r.events.size(), 1u);
    EXPECT_EQ(r.events[0].t_us, 1000 * 64 + 7);
    EXPECT_EQ(r.skipped, 2u);
  }
  {  // EVT 3.0
    const ReadResult r = read_all(dir.save("evt3_base.raw", with_words(
        "% format EVT3;height=720;width=1280\n",
        std::vector<std::uint16_t>{
            0x0014, 0x2800 | 10,  // ADDR_Y 20, ADDR_X 10 ON: before any TIME_HIGH
            0x8005, 0x6064,       // TIME_HIGH 5, TIME_LOW 100: t = 5 << 12 | 100
            0x2800 | 11,          // ADDR_X 11 ON at t
            0x8005,               // TIME_HIGH 5 again (repeated every 16 us)
            0x2800 | 12,          // still at t
            0x8800, 0x6000,       // TIME_HIGH 2048
            0x2800 | 13,
            0x8000, 0x6000,       // TIME_HIGH 0: a drop of exactly 2048 is a wrap
            0x2800 | 14,
        })), 2);
    ASSERT_FALSE(r.error) << r.error->what();
    const std::int64_t t = (5 << 12) | 100;
    const std::vector<Event> expected = {{t, 11, 20, 1}, {t, 12, 20, 1}, {std::int64_t{2048} << 12, 13, 20, 1},
                                         {std::int64_t{1} << 24, 14, 20, 1}};
    ASSERT_EQ(r.events.size(), expected.size());
    EXPECT_TRUE(is_prefix(r.events, expected));
    EXPECT_EQ(r.skipped, 1u);
  }
}

// An EVT 3.0 stream cut after its time base but before its first row
// (ADDR_Y) or vector base (VECT_BASE_X): the events there have no known
// address. They were made up at y = 0 / x = 0.., uncounted; now skipped and
// counted, as the events before the first TIME_HIGH.
TEST(IoFormatsWordStreams, Evt3EventsBeforeTheirRowOrVectorBaseAreSkippedAndCounted) {
  const ScratchDir dir("test_io_formats");
  const std::string path = dir.save("evt3_no_row.raw", with_words(
      "% format EVT3;height=720;width=1280\n",
      std::vector<std::uint16_t>{
          0x8005, 0x6064,    // TIME_HIGH 5, TIME_LOW 100
          0x2800 | 10,       // ADDR_X 10 ON: no row yet
          0x0000 | 20,       // ADDR_Y 20
          0x4000 | 0xFFF,    // VECT_12, 12 events: no vector base yet
          0x2800 | 11,       // ADDR_X 11 ON: an event
          0x3000 | 0x800 | 40,  // VECT_BASE_X 40 ON
          0x5000 | 0x3,      // VECT_8: x = 40, 41
      }));
  const ReadResult r = read_all(path, 4);
  ASSERT_FALSE(r.error) << r.error->what();
  const std::int64_t t = (5 << 12) | 100;
  const std::vector<Event> expected = {{t, 11, 20, 1}, {t, 40, 20, 1}, {t, 41, 20, 1}};
  ASSERT_EQ(r.events.size(), expected.size());
  EXPECT_TRUE(is_prefix(r.events, expected));
  EXPECT_EQ(r.skipped, 13u);
  auto reader = evlife::io::open_event_reader(path);
  std::vector<Event> all(16);
  while (reader->read(all) > 0) {
  }
  EXPECT_EQ(evlife::io::skipped_kinds_text(*reader), "event-before-its-row-or-vector-base 13");
}

TEST(IoFormatsWordStreams, Evt21ByteOrderFromTheWordsThemselves) {
  using evlife::io::Evt21Reader;
  const std::vector<std::uint64_t> words = {evt21_time_high(7), evt21_event(1, 1, 64, 2, 0x00F0F00Fu),
                                            evt21_event(0, 9, 96, 3, 0x80000001u), evt21_time_high(8)};
  const auto bytes_of = [](const auto& ws) {
    std::vector<std::uint8_t> b;
    for (const auto w : ws) {
      for (std::size_t k = 0; k < sizeof w; ++k) b.push_back(static_cast<std::uint8_t>(w >> (8 * k)));
    }
    return b;
  };
  EXPECT_EQ(Evt21Reader::detect_layout(bytes_of(words)), Evt21Reader::Layout::whole_word);
  EXPECT_EQ(Evt21Reader::detect_layout(bytes_of(upper_half_first(words))), Evt21Reader::Layout::upper_half_first);
  // Nothing to go by (no words): one 64-bit word, as GenX320 writes.
  EXPECT_EQ(Evt21Reader::detect_layout({}), Evt21Reader::Layout::whole_word);
}

TEST(IoFormatsWordStreams, DatTimeWrapsTo64Bits) {
  const ScratchDir dir("test_io_formats");
  std::vector<std::uint8_t> bytes;
  const std::string header = "% Width 304\n% Height 240\n";
  bytes.assign(header.begin(), header.end());
  bytes.push_back(0x00);  // type Event2d
  bytes.push_back(8);     // record size
  const auto record = [&](std::uint32_t t, std::uint32_t x, std::uint32_t y, std::uint32_t p) {
    const std::uint32_t w = x | (y << 14) | (p << 28);
    for (int k = 0; k < 4; ++k) bytes.push_back(static_cast<std::uint8_t>(t >> (8 * k)));
    for (int k = 0; k < 4; ++k) bytes.push_back(static_cast<std::uint8_t>(w >> (8 * k)));
  };
  record(0xFFFFFFF0u, 303, 239, 1);
  record(5, 1, 2, 0);
  const ReadResult r = read_all(dir.save("wrap.dat", bytes));
  ASSERT_FALSE(r.error) << r.error->what();
  EXPECT_EQ(*r.sensor, (SensorSize{304, 240}));
  ASSERT_EQ(r.events.size(), 2u);
  EXPECT_EQ(r.events[0].t_us, 0xFFFFFFF0LL);
  EXPECT_EQ(r.events[1].t_us, (std::int64_t{1} << 32) + 5);
  EXPECT_TRUE(r.events[1].x == 1 && r.events[1].y == 2 && r.events[1].p == -1);
}

// One corrupt high bit of a timestamp rises by more than half the clock's
// range: a step back across a wrap, reported at that record, not a wrap at
// the next one that shifts every later event by 71.6 min with no error.
TEST(IoFormatsWordStreams, DatTimeRisingByMoreThanHalfItsRangeIsAStepBack) {
  const ScratchDir dir("test_io_formats");
  std::vector<std::uint8_t> bytes;
  const std::string header = "% Width 304\n% Height 240\n";
  bytes.assign(header.begin(), header.end());
  bytes.push_back(0x00);
  bytes.push_back(8);
  const auto record = [&](std::uint32_t t) {
    for (int k = 0; k < 4; ++k) bytes.push_back(static_cast<std::uint8_t>(t >> (8 * k)));
    for (int k = 0; k < 4; ++k) bytes.push_back(0);
  };
  record(1000);
  record(2000);
  record(0xF0000000u | 3000u);  // the top bits flipped
  record(4000);
  const ReadResult r = read_all(dir.save("flip.dat", bytes), 4096, true);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.events.size(), 2u);
  EXPECT_EQ(r.error->event_index(), 2);
  EXPECT_NE(std::string(r.error->what()).find("backwards"), std::string::npos) << r.error->what();
  EXPECT_NE(std::string(r.error->what()).find("gap of more than 35.8 min"), std::string::npos) << r.error->what();
}

TEST(IoFormatsWordStreams, Evt2TimeHighRisingByMoreThanHalfItsRangeIsAStepBack) {
  const ScratchDir dir("test_io_formats");
  const auto cd = [](std::uint32_t t_low) { return (1u << 28) | (t_low << 22); };
  const std::vector<std::uint32_t> words = {
      0x80000000u | 100u, cd(1),
      0x80000000u | 0x0F000064u, cd(2),  // TIME_HIGH with its top bits flipped
      0x80000000u | 101u, cd(3),
  };
  const ReadResult r =
      read_all(dir.save("flip.raw", with_words("% evt 2.0\n% geometry 640x480\n", words)), 4096, true);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.error->event_index(), 1);
  EXPECT_NE(std::string(r.error->what()).find("gap of more than 143.2 min"), std::string::npos) << r.error->what();
}

// ---- AEDAT 4.0 written here byte by byte (FlatBuffers laid out by hand from
// the format description, independent of the reader's generated code) ----

void put_u16(std::vector<std::uint8_t>& b, std::size_t at, std::uint16_t v) { std::memcpy(&b[at], &v, 2); }
void put_u32(std::vector<std::uint8_t>& b, std::size_t at, std::uint32_t v) { std::memcpy(&b[at], &v, 4); }
void put_i64(std::vector<std::uint8_t>& b, std::size_t at, std::int64_t v) { std::memcpy(&b[at], &v, 8); }

// Size-prefixed IOHeader: compression, dataTablePosition = -1, infoNode = xml.
std::vector<std::uint8_t> io_header(std::int32_t compression, const std::string& xml) {
  std::vector<std::uint8_t> b(44 + 4 + xml.size() + 1);
  b.resize((b.size() + 3) / 4 * 4, 0);
  put_u32(b, 0, static_cast<std::uint32_t>(b.size() - 4));  // size prefix
  put_u32(b, 4, 20);                                        // root table at p+24
  std::memcpy(&b[8], "IOHE", 4);
  put_u16(b, 12, 10);  // vtable: its size, table size, field offsets
  put_u16(b, 14, 20);
  put_u16(b, 16, 4);
  put_u16(b, 18, 8);
  put_u16(b, 20, 16);
  put_u32(b, 24, 24 - 12);  // table -> vtable
  put_u32(b, 28, static_cast<std::uint32_t>(compression));
  put_i64(b, 32, -1);
  put_u32(b, 40, 4);  // -> string at p+44
  put_u32(b, 44, static_cast<std::uint32_t>(xml.size()));
  std::memcpy(&b[48], xml.data(), xml.size());
  return b;
}

// Size-prefixed EventPacket "EVTS" with 16-byte events.
std::vector<std::uint8_t> event_packet(const std::vector<Event>& events) {
  std::vector<std::uint8_t> b(40 + 16 * events.size(), 0);
  put_u32(b, 0, static_cast<std::uint32_t>(b.size() - 4));
  put_u32(b, 4, 16);  // root table at p+20
  std::memcpy(&b[8], "EVTS", 4);
  put_u16(b, 12, 6);
  put_u16(b, 14, 8);
  put_u16(b, 16, 4);
  put_u32(b, 20, 20 - 12);
  put_u32(b, 24, 12);  // -> vector length at p+36, elements at p+40 (8-aligned)
  put_u32(b, 36, static_cast<std::uint32_t>(events.size()));
  for (std::size_t i = 0; i < events.size(); ++i) {
    const std::size_t at = 40 + 16 * i;
    put_i64(b, at, events[i].t_us);
    put_u16(b, at + 8, events[i].x);
    put_u16(b, at + 10, events[i].y);
    b[at + 12] = events[i].p > 0 ? 1 : 0;
  }
  return b;
}

// Size-prefixed TriggerPacket "TRIG": a vector of Trigger tables (field 0
// timestamp int64, field 1 type int8) sharing one vtable, laid out 8-aligned.
struct DvTrigger {
  std::int64_t t_us;
  std::int8_t type;  // dv::TriggerType: 1-3 external input, 4-5 generator, 0 reset, 6-9 APS markers
};
std::vector<std::uint8_t> trigger_packet(const std::vector<DvTrigger>& triggers) {
  const std::size_t n = triggers.size();
  const std::size_t vtable = 32 + 4 * n;
  const std::size_t first = (vtable + 8 + 7) / 8 * 8;
  std::vector<std::uint8_t> b(first + 16 * n, 0);
  put_u32(b, 0, static_cast<std::uint32_t>(b.size() - 4));
  put_u32(b, 4, 16);  // root table at p+20
  std::memcpy(&b[8], "TRIG", 4);
  put_u16(b, 12, 6);  // the root's vtable: elements at +4
  put_u16(b, 14, 8);
  put_u16(b, 16, 4);
  put_u32(b, 20, 20 - 12);
  put_u32(b, 24, 4);  // -> the vector at 28
  put_u32(b, 28, static_cast<std::uint32_t>(n));
  put_u16(b, vtable, 8);  // the triggers' vtable: timestamp at +8, type at +4
  put_u16(b, vtable + 2, 16);
  put_u16(b, vtable + 4, 8);
  put_u16(b, vtable + 6, 4);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t table = first + 16 * i;
    put_u32(b, 32 + 4 * i, static_cast<std::uint32_t>(table - (32 + 4 * i)));
    put_u32(b, table, static_cast<std::uint32_t>(table - vtable));
    b[table + 4] = static_cast<std::uint8_t>(triggers[i].type);
    put_i64(b, table + 8, triggers[i].t_us);
  }
  return b;
}

// A size-prefixed FileDataTable listing `packets` (byte_offset, stream id,
// size): one shared vtable for its definitions, laid out 8-aligned.
struct ListedPacket {
  std::int64_t byte_offset;
  std::int32_t stream;
  std::int32_t size;
};
std::vector<std::uint8_t> file_table(const std::vector<ListedPacket>& packets) {
  const std::size_t n = packets.size();
  const std::size_t first = (44 + 4 * n + 7) / 8 * 8;  // the first definition table
  std::vector<std::uint8_t> b(first + 48 * n, 0);
  put_u32(b, 0, static_cast<std::uint32_t>(b.size() - 4));  // size prefix
  put_u32(b, 4, 16 - 4);                                    // root table at 16
  put_u16(b, 8, 6);  // the root's vtable: its size, the table's size, field 0 at +4
  put_u16(b, 10, 8);
  put_u16(b, 12, 4);
  put_u32(b, 16, 16 - 8);   // root -> its vtable
  put_u32(b, 20, 40 - 20);  // -> the vector at 40
  const std::uint16_t fields[] = {14, 48, 8, 16, 24, 32, 40};  // definitions' vtable at 24
  for (std::size_t i = 0; i < 7; ++i) put_u16(b, 24 + 2 * i, fields[i]);
  put_u32(b, 40, static_cast<std::uint32_t>(n));
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t table = first + 48 * i;
    put_u32(b, 44 + 4 * i, static_cast<std::uint32_t>(table - (44 + 4 * i)));
    put_u32(b, table, static_cast<std::uint32_t>(table - 24));
    put_i64(b, table + 8, packets[i].byte_offset);
    put_u32(b, table + 16, static_cast<std::uint32_t>(packets[i].stream));
    put_u32(b, table + 20, static_cast<std::uint32_t>(packets[i].size));
  }
  return b;
}

// The file table a writer appends: none (a recording cut short), dv-processing's
// (offsets of the packets' data, compressed as they are), jAER's (offsets of
// their 8-byte headers, uncompressed: Aedat4FileOutputStream).
enum class FileTable { none, dv, jaer };

// `triggers[k]`, if given, follows event packet k as a packet of trigger stream 5;
// `second_camera`: each event packet again on stream 9, a second EVTS stream.
std::vector<std::uint8_t> aedat4_file(std::int32_t compression, const std::vector<std::vector<Event>>& packets,
                                      FileTable table = FileTable::none,
                                      const std::vector<std::vector<DvTrigger>>& triggers = {},
                                      bool second_camera = false) {
  const std::string second =
      second_camera ? "<node name=\"9\" path=\"/mainloop/Recorder/outInfo/9/\">"
                      "<attr key=\"typeIdentifier\" type=\"string\">EVTS</attr></node>"
                    : "";
  const std::string xml =
      "<dv version=\"2.0\"><node name=\"outInfo\" path=\"/mainloop/Recorder/outInfo/\">"
      "<node name=\"3\" path=\"/mainloop/Recorder/outInfo/3/\">"
      "<attr key=\"typeIdentifier\" type=\"string\">IMUS</attr></node>"
      "<node name=\"5\" path=\"/mainloop/Recorder/outInfo/5/\">"
      "<attr key=\"typeIdentifier\" type=\"string\">TRIG</attr></node>"
      "<node name=\"7\" path=\"/mainloop/Recorder/outInfo/7/\">"
      "<attr key=\"typeIdentifier\" type=\"string\">EVTS</attr>"
      "<node name=\"info\" path=\"/mainloop/Recorder/outInfo/7/info/\">"
      "<attr key=\"sizeX\" type=\"int\">346</attr><attr key=\"sizeY\" type=\"int\">260</attr>"
      "</node></node>" + second + "</node></dv>";
  std::vector<std::uint8_t> file = {'#', '!', 'A', 'E', 'R', '-', 'D', 'A', 'T', '4', '.', '0', '\r', '\n'};
  const auto header = io_header(compression, xml);
  file.insert(file.end(), header.begin(), header.end());
  const auto compressed = [&](std::vector<std::uint8_t> payload) {
    if (compression == 3) {
      std::vector<std::uint8_t> z(ZSTD_compressBound(payload.size()));
      z.resize(ZSTD_compress(z.data(), z.size(), payload.data(), payload.size(), 3));
      payload = z;
    }
    return payload;
  };
  std::vector<ListedPacket> listed;
  const auto add_packet = [&](std::int32_t stream, const std::vector<std::uint8_t>& data) {
    const std::vector<std::uint8_t> payload = compressed(data);
    const auto at = static_cast<std::int64_t>(file.size());
    listed.push_back({table == FileTable::jaer ? at : at + 8, stream, static_cast<std::int32_t>(payload.size())});
    std::vector<std::uint8_t> head(8);
    put_u32(head, 0, static_cast<std::uint32_t>(stream));
    put_u32(head, 4, static_cast<std::uint32_t>(payload.size()));
    file.insert(file.end(), head.begin(), head.end());
    file.insert(file.end(), payload.begin(), payload.end());
  };
  for (std::size_t k = 0; k < packets.size(); ++k) {
    add_packet(3, std::vector<std::uint8_t>(100, 0xAB));  // an IMU packet: skipped
    add_packet(7, event_packet(packets[k]));
    if (k < triggers.size()) add_packet(5, trigger_packet(triggers[k]));
    if (second_camera) add_packet(9, event_packet(packets[k]));
  }
  if (table != FileTable::none) {
    put_i64(file, 14 + 32, static_cast<std::int64_t>(file.size()));  // io_header()'s dataTablePosition
    const std::vector<std::uint8_t> bytes = table == FileTable::dv ? compressed(file_table(listed)) : file_table(listed);
    file.insert(file.end(), bytes.begin(), bytes.end());
  }
  return file;
}

// The packets of a file aedat4_file() wrote (no file table): each one's
// offset (of its 8-byte header), stream and size, in file order; and where
// they end.
struct WrittenPacket {
  std::size_t at;
  std::uint32_t stream;
  std::uint32_t size;
};
std::vector<WrittenPacket> packets_of(const std::vector<std::uint8_t>& bytes, std::size_t* end = nullptr) {
  std::uint32_t header_bytes;
  std::memcpy(&header_bytes, &bytes[14], 4);
  std::vector<WrittenPacket> packets;
  std::size_t offset = 14 + 4 + header_bytes;
  while (offset + 8 <= bytes.size()) {
    WrittenPacket p{offset, 0, 0};
    std::memcpy(&p.stream, &bytes[offset], 4);
    std::memcpy(&p.size, &bytes[offset + 4], 4);
    packets.push_back(p);
    offset += 8 + p.size;
  }
  if (end != nullptr) *end = offset;
  return packets;
}
/// The offset of the last (or first) packet of `stream`; 0 for none.
std::size_t packet_of_stream(const std::vector<std::uint8_t>& bytes, std::uint32_t stream, bool first = false) {
  std::size_t found = 0;
  for (const WrittenPacket& p : packets_of(bytes))
    if (p.stream == stream && (found == 0 || !first)) found = p.at;
  return found;
}

TEST(IoFormatsAedat4Synthetic, UncompressedAndZstdPacketsDecode) {
  const ScratchDir dir("test_io_formats");
  std::vector<std::vector<Event>> packets(3);
  std::int64_t t_us = 1'700'000'000'000'000;
  for (std::size_t k = 0; k < packets.size(); ++k) {
    for (int i = 0; i < 1000 + 77 * static_cast<int>(k); ++i) {
      t_us += i % 3;
      packets[k].push_back(Event{t_us, static_cast<std::uint16_t>((i * 7) % 346),
                                 static_cast<std::uint16_t>((i * 13) % 260), i % 2 ? std::int8_t{1} : std::int8_t{-1}});
    }
  }
  std::vector<Event> expected;
  for (const auto& p : packets) expected.insert(expected.end(), p.begin(), p.end());
  // Every file table the writers append: their offsets name the packets'
  // data or headers, compressed or not; the reader checks they end at it.
  for (const auto& [compression, table] : std::vector<std::pair<std::int32_t, FileTable>>{
           {0, FileTable::none}, {0, FileTable::dv}, {0, FileTable::jaer},  // NONE
           {3, FileTable::none}, {3, FileTable::dv}, {3, FileTable::jaer}}) {  // ZSTD
    const ReadResult r = read_all(dir.save("synthetic.aedat4", aedat4_file(compression, packets, table)), 500, true);
    ASSERT_FALSE(r.error) << "compression " << compression << ", table " << static_cast<int>(table) << ": "
                          << r.error->what();
    EXPECT_EQ(r.format, "aedat4");
    ASSERT_TRUE(r.sensor.has_value());
    EXPECT_EQ(*r.sensor, (SensorSize{346, 260}));
    EXPECT_EQ(r.skipped, 3u);
    ASSERT_EQ(r.events.size(), expected.size());
    EXPECT_TRUE(is_prefix(r.events, expected));
  }
}

// An event packet whose elements field is damaged reads as one without
// events: it was passed over uncounted (8 of 16 events, exit 0, the skipped
// line unchanged). Now counted and shown as a skipped record of its kind.
TEST(IoFormatsAedat4Synthetic, AnEventPacketWithoutEventsIsCountedAsSkipped) {
  const ScratchDir dir("test_io_formats");
  const std::vector<std::vector<Event>> packets = {std::vector<Event>(8, Event{10, 1, 2, 1}), {},
                                                   std::vector<Event>(8, Event{20, 3, 4, -1})};
  const std::string path = dir.save("empty_packet.aedat4", aedat4_file(0, packets));
  const ReadResult r = read_all(path);
  ASSERT_FALSE(r.error) << r.error->what();
  EXPECT_EQ(r.events.size(), 16u);
  EXPECT_EQ(r.skipped, 4u);  // the file's 3 other packets and the empty one
  const auto reader = evlife::io::open_event_reader(path);
  std::vector<Event> block(64);
  while (reader->read(block) > 0) {
  }
  const auto kinds = reader->skipped_record_kinds();
  ASSERT_FALSE(kinds.empty());
  EXPECT_EQ(kinds.back().kind, "event-packet-without-events");
  EXPECT_EQ(kinds.back().count, 1u);
}

// An event packet whose count was shortened by a damaged byte read its
// first events and dropped the rest unsaid (exit 0). The elements vector
// ends every written packet, so room for events after it is a fault.
TEST(IoFormatsAedat4Synthetic, AShortenedEventCountIsAnErrorNotALoss) {
  const ScratchDir dir("test_io_formats");
  const std::vector<std::vector<Event>> packets = {std::vector<Event>(8, Event{10, 1, 2, 1}),
                                                   std::vector<Event>(8, Event{20, 3, 4, -1})};
  std::vector<std::uint8_t> bytes = aedat4_file(0, packets);
  const std::size_t second = packet_of_stream(bytes, 7);
  ASSERT_EQ(bytes[second + 8 + 36], 8u);  // event_packet()'s vector length
  for (const std::uint8_t count : {std::uint8_t{7}, std::uint8_t{1}}) {
    bytes[second + 8 + 36] = count;
    const ReadResult r = read_all(dir.save("short_count.aedat4", bytes));
    ASSERT_TRUE(r.error) << "count " << int{count} << ": read " << r.events.size() << " events, no error";
    EXPECT_EQ(r.events.size(), 8u);  // the first packet's
    EXPECT_NE(std::string(r.error->what()).find("counts " + std::to_string(count) + " events"), std::string::npos)
        << r.error->what();
    EXPECT_NE(std::string(r.error->what()).find("byte offset " + std::to_string(second)), std::string::npos)
        << r.error->what();
  }
}

// The trigger stream's packets were skipped undecoded: `triggers 0` for a
// recording with external triggers. Only the external input's edges and
// pulses count (as AEDAT 3's special events), not the generator's edges,
// timestamp resets or APS frame and exposure markers.
TEST(IoFormatsAedat4Synthetic, ExternalTriggersAreCountedFromTheTriggerPackets) {
  const ScratchDir dir("test_io_formats");
  const std::vector<std::vector<Event>> packets = {std::vector<Event>(40, Event{10, 1, 2, 1}),
                                                   std::vector<Event>(30, Event{20, 3, 4, -1})};
  std::vector<std::vector<DvTrigger>> triggers(2);
  for (std::int8_t type = 0; type <= 9; ++type) triggers[0].push_back({10 + type, type});  // 3 external
  triggers[1] = {{21, 1}, {22, 2}, {23, 8}};  // 2 external
  for (const std::int32_t compression : {0, 3}) {
    const std::string path =
        dir.save("triggers.aedat4", aedat4_file(compression, packets, FileTable::dv, triggers, /*second_camera=*/true));
    auto reader = evlife::io::open_event_reader(path);
    std::vector<Event> all(100);
    std::size_t events = 0;
    while (const std::size_t n = reader->read(all)) events += n;
    EXPECT_EQ(events, 70u) << compression;  // the first EVTS stream's
    EXPECT_EQ(reader->trigger_count(), 5u) << compression;
    // (A second camera's polarity packets were "other-packet".)
    EXPECT_EQ(evlife::io::skipped_kinds_text(*reader),
              "imu-packet 2, trigger-packet 2, event-packet-of-another-stream 2")
        << compression;
  }
}

// A trigger packet that does not verify is an input error at its offset,
// after the events before it (it was skipped unseen before it was decoded).
TEST(IoFormatsAedat4Synthetic, CorruptTriggerPacketIsReported) {
  const ScratchDir dir("test_io_formats");
  const std::vector<std::vector<Event>> packets = {std::vector<Event>(40, Event{10, 1, 2, 1}),
                                                   std::vector<Event>(30, Event{20, 3, 4, -1})};
  std::vector<std::uint8_t> bytes = aedat4_file(0, packets, FileTable::none, {{{11, 1}}, {{21, 1}}});
  const std::size_t first_trigger_packet = packet_of_stream(bytes, 5, /*first=*/true);
  ASSERT_NE(first_trigger_packet, 0u);
  put_u32(bytes, first_trigger_packet + 8 + 32, 0x7FFF'0000);  // the first trigger's offset: past the packet
  const ReadResult r = read_all(dir.save("bad_trigger.aedat4", bytes), 64);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->byte_offset(), static_cast<std::int64_t>(first_trigger_packet)) << r.error->what();
  EXPECT_NE(std::string(r.error->what()).find("trigger packet does not verify"), std::string::npos)
      << r.error->what();
  EXPECT_EQ(r.events.size(), 40u);
}

// A compressed packet holds one frame, as DV writes it: bytes after it (a
// second frame, garbage) were never read, exit 0. Now an input error at the
// packet, after the events before it.
TEST(IoFormatsAedat4Synthetic, BytesAfterAPacketsCompressedFrameAreAnError) {
  const ScratchDir dir("test_io_formats");
  const std::vector<Event> events(500, Event{5, 1, 2, 1});
  std::vector<std::uint8_t> bytes = aedat4_file(3, {events, events});
  std::size_t end = 0;
  const std::size_t last_event_packet = packets_of(bytes, &end).back().at;
  ASSERT_EQ(end, bytes.size());  // the file ends with an event packet: 8 bytes appended to it
  ASSERT_EQ(last_event_packet, packet_of_stream(bytes, 7));
  std::uint32_t size;
  std::memcpy(&size, &bytes[last_event_packet + 4], 4);
  put_u32(bytes, last_event_packet + 4, size + 8);
  bytes.insert(bytes.end(), 8, 0x42);
  const ReadResult r = read_all(dir.save("trailing.aedat4", bytes));
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->byte_offset(), static_cast<std::int64_t>(last_event_packet)) << r.error->what();
  EXPECT_NE(std::string(r.error->what()).find("8 bytes after its compressed frame"), std::string::npos)
      << r.error->what();
  EXPECT_EQ(r.events.size(), 500u);
}

TEST(IoFormatsAedat4Synthetic, EventOutsideTheStatedSensorIsReported) {
  const ScratchDir dir("test_io_formats");
  std::vector<Event> good(300, Event{10, 345, 259, 1});
  std::vector<Event> second(200, Event{20, 3, 4, -1});
  second[123].x = 346;  // sensor is 346 wide: x must be < 346
  const ReadResult r = read_all(dir.save("outside.aedat4", aedat4_file(0, {good, second})), 64);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->event_index(), 300 + 123) << r.error->what();
  EXPECT_NE(std::string(r.error->what()).find("x=346"), std::string::npos) << r.error->what();
  ASSERT_EQ(r.events.size(), 300u + 123u);
  EXPECT_EQ(r.events.back().t_us, 20);
}

TEST(IoFormatsAedat4Synthetic, CorruptZstdPacketIsReported) {
  const ScratchDir dir("test_io_formats");
  std::vector<Event> events(500, Event{5, 1, 2, 1});
  std::vector<std::uint8_t> bytes = aedat4_file(3, {events, events});
  // Break the zstd magic of the last packet (the file ends with it).
  std::size_t end = 0;
  const std::size_t last_event_packet = packet_of_stream(bytes, 7);
  ASSERT_EQ(packets_of(bytes, &end).back().at, last_event_packet);
  ASSERT_EQ(end, bytes.size());
  bytes[last_event_packet + 8] ^= 0xFF;
  const ReadResult r = read_all(dir.save("bad_zstd.aedat4", bytes));
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->byte_offset(), static_cast<std::int64_t>(last_event_packet)) << r.error->what();
  EXPECT_NE(std::string(r.error->what()).find("Zstd"), std::string::npos) << r.error->what();
  EXPECT_EQ(r.events.size(), 500u);  // the first packet, before the fault
}

// ---- truncation: clean error at the right byte, every good event first ----

// Word-stream formats: cutting inside a word must name that word's offset;
// the events before are exactly those of the complete decode.
void expect_truncation_error(const std::string& name, const std::string& sample, std::size_t cut,
                             std::size_t expected_offset, const ScratchDir& dir,
                             const std::vector<Event>& full) {
  std::vector<std::uint8_t> bytes = load(sample);
  bytes.resize(cut);
  const ReadResult r = read_all(dir.save(name, bytes), 1000);
  ASSERT_TRUE(r.error) << name << " cut at " << cut;
  EXPECT_EQ(r.error->byte_offset(), static_cast<std::int64_t>(expected_offset)) << r.error->what();
  EXPECT_NE(std::string(r.error->what()).find("truncated"), std::string::npos) << r.error->what();
  EXPECT_EQ(r.error->event_index(), static_cast<std::int64_t>(r.events.size()));
  ASSERT_LE(r.events.size(), full.size());
  EXPECT_TRUE(is_prefix(r.events, full));
}

TEST(IoFormatsTruncation, Evt2CutInsideAWord) {
  const ScratchDir dir("test_io_formats");
  const std::vector<Event> full = read_all(kEvt2).events;
  const std::vector<std::uint8_t> bytes = load(kEvt2);
  const std::size_t data = prophesee_header_end(bytes);
  for (const std::size_t words : {0u, 1u, 1000u, 123'457u, 542'000u}) {
    // Independent count: CD words (type 0/1) among the complete words kept.
    std::size_t cd = 0;
    for (std::size_t k = 0; k < words; ++k) cd += (bytes[data + 4 * k + 3] >> 4) <= 1;
    expect_truncation_error("evt2_cut.raw", kEvt2, data + 4 * words + 3, data + 4 * words, dir, full);
    EXPECT_EQ(read_all(dir.save("evt2_cut2.raw", std::vector<std::uint8_t>(bytes.begin(),
                                 bytes.begin() + static_cast<std::ptrdiff_t>(data + 4 * words + 1))))
                  .events.size(),
              cd);
  }
}

// A recording cut while it is being read (a copy still in progress, a disk
// filling up): its stream ends in an error after every event before the cut
// (the file's size at opening is known), never in a quiet end of file.
TEST(IoFormatsTruncation, AFileCutWhileBeingReadEndsInAnErrorAfterItsEvents) {
  const ScratchDir dir("test_io_formats");
  const std::vector<std::uint8_t> bytes = load(kEvt2);
  const std::size_t data = prophesee_header_end(bytes);
  const std::size_t kept_words = 300'000;  // past the reader's first 1 MiB buffer
  ASSERT_GT(data + 4 * kept_words, std::size_t{1} << 20);
  ASSERT_LT(data + 4 * kept_words, bytes.size());
  std::size_t cd = 0;  // independent count of the CD words kept
  for (std::size_t k = 0; k < kept_words; ++k) cd += (bytes[data + 4 * k + 3] >> 4) <= 1;
  for (const bool checked : {false, true}) {
    const std::string path = dir.save("evt2_shrinking.raw", bytes);
    auto reader = checked ? evlife::io::open_event_reader(path) : evlife::io::open_unchecked_event_reader(path);
    std::vector<Event> chunk(1000), events;
    std::size_t n = reader->read(chunk);
    events.insert(events.end(), chunk.begin(), chunk.begin() + static_cast<std::ptrdiff_t>(n));
    fs::resize_file(path, data + 4 * kept_words);
    std::optional<ReadError> error;
    try {
      while ((n = reader->read(chunk)) > 0) {
        events.insert(events.end(), chunk.begin(), chunk.begin() + static_cast<std::ptrdiff_t>(n));
      }
    } catch (const ReadError& e) {
      error = e;
    }
    ASSERT_TRUE(error) << "checked " << checked << ": the cut passed for the end of the file";
    EXPECT_NE(std::string(error->what()).find("cut while being read"), std::string::npos) << error->what();
    EXPECT_EQ(error->byte_offset(), static_cast<std::int64_t>(data + 4 * kept_words)) << error->what();
    EXPECT_EQ(events.size(), cd) << "checked " << checked;
    EXPECT_EQ(error->event_index(), static_cast<std::int64_t>(cd)) << error->what();
    EXPECT_TRUE(is_prefix(events, read_all(kEvt2).events));
  }
}

TEST(IoFormatsTruncation, Evt3CutInsideAWord) {
  const ScratchDir dir("test_io_formats");
  const std::vector<Event> full = read_all(kEvt3).events;
  const std::size_t data = prophesee_header_end(load(kEvt3));
  for (const std::size_t words : {0u, 7u, 50'001u, 308'000u}) {
    expect_truncation_error("evt3_cut.raw", kEvt3, data + 2 * words + 1, data + 2 * words, dir, full);
  }
}

TEST(IoFormatsTruncation, DatCutInsideARecord) {
  const ScratchDir dir("test_io_formats");
  const std::vector<Event> full = read_all(kDat).events;
  const std::size_t data = prophesee_header_end(load(kDat)) + 2;  // + type and size bytes
  for (const std::size_t records : {0u, 1u, 2000u, 4406u}) {
    for (const std::size_t extra : {1u, 7u}) {
      expect_truncation_error("dat_cut.dat", kDat, data + 8 * records + extra, data + 8 * records,
                              dir, full);
    }
  }
}

// The header's dataTablePosition says where the packets end. Pointed at an
// earlier packet, the reading stopped there without a word (109,953 of
// 111,954 events); the file table found there must list packets that end
// there. A table cut short is a fault too, after every event.
TEST(IoFormatsTruncation, Aedat4TableThatIsNotWhereThePacketsEnd) {
  const ScratchDir dir("test_io_formats");
  const std::vector<Event> full = read_all(kAedat4).events;
  const std::vector<std::uint8_t> bytes = load(kAedat4);
  constexpr std::int64_t kTable = 945'243, kLastEventPacket = 928'332;  // sample.aedat4's
  std::int64_t stated = 0;
  const auto field = std::search(bytes.begin(), bytes.begin() + 2334, reinterpret_cast<const std::uint8_t*>(&kTable),
                                 reinterpret_cast<const std::uint8_t*>(&kTable) + 8);
  ASSERT_NE(field, bytes.begin() + 2334) << "no dataTablePosition of " << kTable << " in the header";
  std::memcpy(&stated, &*field, 8);
  ASSERT_EQ(stated, kTable);
  std::vector<std::uint8_t> early = bytes;
  std::memcpy(&early[static_cast<std::size_t>(field - bytes.begin())], &kLastEventPacket, 8);
  const ReadResult r = read_all(dir.save("early_table.aedat4", early), 1000);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->byte_offset(), kLastEventPacket) << r.error->what();
  EXPECT_NE(std::string(r.error->what()).find("the header's dataTablePosition, byte 928332, holds no file table listing "
                                              "the packets before it"),
            std::string::npos)
      << r.error->what();
  EXPECT_LT(r.events.size(), full.size());
  EXPECT_TRUE(is_prefix(r.events, full));
  const std::vector<std::uint8_t> cut(bytes.begin(), bytes.begin() + kTable + 100);
  const ReadResult c = read_all(dir.save("cut_table.aedat4", cut), 1000);
  ASSERT_TRUE(c.error);
  EXPECT_EQ(c.error->byte_offset(), kTable) << c.error->what();
  EXPECT_EQ(c.events.size(), full.size());
}

// Bytes after the file table would be lost unseen (a second recording
// appended, as `cat a.aedat4 b.aedat4` makes, or garbage): an error at the
// table's end, after every event of the file, as the other formats give at a
// join. (The reader took them for the table's and read one recording, exit 0.)
TEST(IoFormatsTruncation, Aedat4BytesAfterTheFileTableAreAnError) {
  const ScratchDir dir("test_io_formats");
  const std::vector<Event> full = read_all(kAedat4).events;
  const std::vector<std::uint8_t> bytes = load(kAedat4);
  std::vector<std::uint8_t> twice = bytes;
  twice.insert(twice.end(), bytes.begin(), bytes.end());
  std::vector<std::uint8_t> junk = bytes;
  for (int i = 0; i < 5000; ++i) junk.push_back(static_cast<std::uint8_t>(i * 37 + 11));
  for (const auto& [name, file] : {std::pair{"twice.aedat4", twice}, std::pair{"junk.aedat4", junk}}) {
    const ReadResult r = read_all(dir.save(name, file), 1000);
    ASSERT_TRUE(r.error) << name;
    EXPECT_EQ(r.error->byte_offset(), static_cast<std::int64_t>(bytes.size())) << r.error->what();
    EXPECT_NE(std::string(r.error->what()).find(std::to_string(file.size() - bytes.size()) + " bytes after the file table"),
              std::string::npos)
        << r.error->what();
    EXPECT_EQ(r.events.size(), full.size()) << name;
  }
}

TEST(IoFormatsTruncation, Aedat4CutAnywhere) {
  const ScratchDir dir("test_io_formats");
  const std::vector<Event> full = read_all(kAedat4).events;
  const std::vector<std::uint8_t> bytes = load(kAedat4);
  // Inside the magic, the header size, the header, packets, the last packet.
  for (const std::size_t cut : {5u, 16u, 1000u, 2334u + 4u, 2334u + 8u + 100u, 300'001u, 945'000u}) {
    std::vector<std::uint8_t> cut_bytes(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(cut));
    const ReadResult r = read_all(dir.save("cut.aedat4", cut_bytes), 1000);
    ASSERT_TRUE(r.error) << "cut at " << cut;
    EXPECT_LE(r.error->byte_offset(), static_cast<std::int64_t>(cut)) << r.error->what();
    ASSERT_LE(r.events.size(), full.size());
    EXPECT_TRUE(is_prefix(r.events, full));
    if (cut > 300'000u) {
      EXPECT_GT(r.events.size(), 10'000u);  // the packets before the cut
    }
  }
}

TEST(IoFormatsTruncation, HeaderOnlyOrEmptyFilesFailCleanly) {
  const ScratchDir dir("test_io_formats");
  for (const std::string& sample : {kEvt2, kEvt3, kDat}) {
    std::vector<std::uint8_t> bytes = load(sample);
    bytes.resize(prophesee_header_end(bytes) - 3);  // inside the last header line
    const ReadResult r = read_all(dir.save("header_cut" + fs::path(sample).extension().string(), bytes));
    EXPECT_TRUE(r.error) << sample;
  }
}

// ---- corrupt data ----

// Rewrites the top 4 bits of the little-endian word of `word_bytes` at `offset`.
void set_type(std::vector<std::uint8_t>& bytes, std::size_t offset, std::size_t word_bytes, std::uint8_t type) {
  std::uint8_t& top = bytes[offset + word_bytes - 1];
  top = static_cast<std::uint8_t>((top & 0x0F) | (type << 4));
}

TEST(IoFormatsCorruption, UnknownWordTypesAreReportedAtTheirOffset) {
  const ScratchDir dir("test_io_formats");
  struct Case {
    std::string sample;
    std::size_t word_bytes;
    std::uint8_t bad_type;
  };
  for (const Case& c : {Case{kEvt2, 4, 0x2}, Case{kEvt3, 2, 0x1}}) {
    const std::vector<Event> full = read_all(c.sample).events;
    std::vector<std::uint8_t> bytes = load(c.sample);
    const std::size_t at = prophesee_header_end(bytes) + c.word_bytes * 40'000;
    set_type(bytes, at, c.word_bytes, c.bad_type);
    const ReadResult r = read_all(dir.save("bad_type.raw", bytes), 999);
    ASSERT_TRUE(r.error) << c.sample;
    EXPECT_EQ(r.error->byte_offset(), static_cast<std::int64_t>(at)) << r.error->what();
    EXPECT_NE(std::string(r.error->what()).find("unknown"), std::string::npos) << r.error->what();
    EXPECT_GT(r.events.size(), 1000u);
    EXPECT_TRUE(is_prefix(r.events, full));
  }
}

// `bytes` with `n` bytes from `at` on set to `fill`, read in buffers of
// `buffer` events: the read must fail at `at`, its message saying `said`.
ReadResult read_filled_at(const ScratchDir& dir, std::vector<std::uint8_t> bytes, std::size_t at, std::size_t n,
                          std::uint8_t fill, const std::string& said, std::size_t buffer) {
  std::fill(bytes.begin() + static_cast<std::ptrdiff_t>(at), bytes.begin() + static_cast<std::ptrdiff_t>(at + n), fill);
  const ReadResult r = read_all(dir.save("filled.raw", bytes), buffer);
  EXPECT_TRUE(r.error) << "filled at " << at;
  if (r.error) {
    EXPECT_EQ(r.error->byte_offset(), static_cast<std::int64_t>(at)) << r.error->what();
    EXPECT_NE(std::string(r.error->what()).find(said), std::string::npos) << r.error->what();
  }
  return r;
}

// Bytes overwritten with 0xFF (a bad flash sector, a buffer never filled)
// read as CONTINUED words. A CONTINUED word only goes on from an OTHERS word,
// so a run of them after events is an error at its first word, after the
// events before it; an OTHERS word with its CONTINUED words is skipped.
TEST(IoFormatsCorruption, RunsOf0xFFAreReportedAtTheirFirstWord) {
  const ScratchDir dir("test_io_formats");
  for (const auto& [sample, word_bytes] : {std::pair{kEvt2, std::size_t{4}}, std::pair{kEvt3, std::size_t{2}}}) {
    const std::vector<Event> full = read_all(sample).events;
    std::vector<std::uint8_t> bytes = load(sample);
    const std::size_t data = prophesee_header_end(bytes);
    const std::size_t at = data + word_bytes * 40'000;
    const ReadResult r = read_filled_at(dir, bytes, at, 4096, 0xFF, "CONTINUED", 999);
    EXPECT_GT(r.events.size(), 1000u);
    EXPECT_TRUE(is_prefix(r.events, full));

    std::fill(bytes.begin() + static_cast<std::ptrdiff_t>(data), bytes.end(), std::uint8_t{0xFF});
    const ReadResult all = read_all(dir.save("all_ff.raw", bytes));
    ASSERT_TRUE(all.error) << sample;
    EXPECT_EQ(all.error->byte_offset(), static_cast<std::int64_t>(data)) << all.error->what();
    EXPECT_TRUE(all.events.empty());
  }
  // OTHERS, then two CONTINUED words: three skipped records between two events.
  const ReadResult evt2 = read_all(dir.save("others2.raw", with_words("% evt 2.0\n% geometry 640x480\n",
      std::vector<std::uint32_t>{0x80000001u, 0x10000000u | (5u << 11) | 6u, 0xE0000000u, 0xFFFFFFFFu,
                                 0xF0000000u, 0x00000000u | (7u << 11) | 8u})));
  ASSERT_FALSE(evt2.error) << evt2.error->what();
  EXPECT_EQ(evt2.events.size(), 2u);
  EXPECT_EQ(evt2.skipped, 3u);
  const ReadResult evt3 = read_all(dir.save("others3.raw", with_words("% evt 3.0\n% geometry 640x480\n",
      std::vector<std::uint16_t>{0x8001, 0x0003, 0x2004, 0xE000, 0x7FFF, 0xFFFF, 0x2005})));
  ASSERT_FALSE(evt3.error) << evt3.error->what();
  EXPECT_EQ(evt3.events.size(), 2u);
  EXPECT_EQ(evt3.skipped, 3u);
}

// A block of the file never written (power lost while recording: the file
// system hands back zeros) reads in EVT 2.0 as OFF events at (0, 0), all at
// one time: an error at the block's first word instead, wherever the block
// lies in the reader's buffer. One zero word is an event, also the last.
TEST(IoFormatsCorruption, ZeroFilledEvt2AndEvt21DataIsReportedAtItsFirstWord) {
  const ScratchDir dir("test_io_formats");
  const std::vector<Event> full = read_all(kEvt2).events;
  const std::vector<std::uint8_t> bytes = load(kEvt2);
  const std::size_t data = prophesee_header_end(bytes);
  // Around the end of the reader's first 1 MiB buffer (at file offset 1 MiB:
  // a block there starts with the buffer's last word), and far from it.
  std::vector<std::size_t> starts = {data + 4 * 40'000};
  for (std::size_t at = (std::size_t{1} << 20) - 16; at <= (std::size_t{1} << 20) + 16; at += 4)
    starts.push_back(at - (at - data) % 4);
  for (const std::size_t at : starts) {
    const ReadResult r = read_filled_at(dir, bytes, at, 8, 0x00, "zero-filled", 4096);
    // Every event before the block, and none of it.
    const std::vector<std::uint8_t> before(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(at));
    EXPECT_EQ(r.events.size(), read_all(dir.save("before.raw", before)).events.size()) << at;
    EXPECT_TRUE(is_prefix(r.events, full)) << at;
  }
  const std::string header = "% evt 2.0\n% geometry 640x480\n";
  const ReadResult lone = read_all(dir.save("lone_zero.raw", with_words(header,
      std::vector<std::uint32_t>{0x80000001u, 0u, 0x10000000u | (5u << 11) | 6u, 0u})));
  ASSERT_FALSE(lone.error) << lone.error->what();
  ASSERT_EQ(lone.events.size(), 3u);
  EXPECT_TRUE(lone.events[0].x == 0 && lone.events[0].y == 0 && lone.events[0].p == -1 && lone.events[0].t_us == 64);
  const std::string header21 = "% evt 2.1\n% geometry 320x320\n";
  const std::vector<std::uint64_t> words21 = {evt21_time_high(1), evt21_event(1, 0, 0, 0, 1), 0, 0,
                                              evt21_event(1, 0, 32, 0, 1)};
  const ReadResult r21 = read_all(dir.save("zeros21.raw", with_words(header21, words21)));
  ASSERT_TRUE(r21.error);
  EXPECT_EQ(r21.error->byte_offset(), static_cast<std::int64_t>(header21.size() + 2 * 8)) << r21.error->what();
  EXPECT_EQ(r21.events.size(), 1u);
}

// EVT 3.0's zero word sets row y=0; two in a row (the row set again with
// nothing between) is what no encoder writes and a lost write leaves. The
// error names the block's first word (across ROS messages: RosPayloads).
TEST(IoFormatsCorruption, ZeroFilledEvt3DataIsReportedAtItsFirstWord) {
  const ScratchDir dir("test_io_formats");
  const std::vector<Event> full = read_all(kEvt3).events;
  const std::vector<std::uint8_t> bytes = load(kEvt3);
  const std::size_t data = prophesee_header_end(bytes);
  for (const std::size_t at : {data + 2 * 40'000, data + 2 * 40'001, bytes.size() - 4096}) {
    const ReadResult r = read_filled_at(dir, bytes, at, 4096, 0x00, "zero-filled", 999);
    const std::vector<std::uint8_t> before(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(at));
    EXPECT_EQ(r.events.size(), read_all(dir.save("before.raw", before)).events.size()) << at;
    EXPECT_TRUE(is_prefix(r.events, full)) << at;
  }
  // One zero word (row 0) between events is a row address, not a fault.
  const ReadResult lone = read_all(dir.save("lone_zero3.raw", with_words("% evt 3.0\n% geometry 640x480\n",
      std::vector<std::uint16_t>{0x8001, 0x0003, 0x2004, 0x0000, 0x2005, 0x0000, 0x2006})));
  ASSERT_FALSE(lone.error) << lone.error->what();
  ASSERT_EQ(lone.events.size(), 3u);
  EXPECT_TRUE(lone.events[1].x == 5 && lone.events[1].y == 0 && lone.events[2].x == 6 && lone.events[2].y == 0);
}

TEST(IoFormatsCorruption, DatPolarityOutOfRangeIsReported) {
  const ScratchDir dir("test_io_formats");
  std::vector<std::uint8_t> bytes = load(kDat);
  const std::size_t data = prophesee_header_end(bytes) + 2;
  bytes[data + 8 * 100 + 7] |= 0x50;  // p = w >> 28 becomes >= 5
  const ReadResult r = read_all(dir.save("bad_p.dat", bytes));
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->byte_offset(), static_cast<std::int64_t>(data + 800)) << r.error->what();
  EXPECT_EQ(r.events.size(), 100u);
}

TEST(IoFormatsCorruption, Aedat4BadPacketSizeIsReported) {
  const ScratchDir dir("test_io_formats");
  std::vector<std::uint8_t> bytes = load(kAedat4);
  const std::size_t first_packet = 14 + 4 + 2316;  // magic + header size + header
  bytes[first_packet + 7] = 0x7F;                  // size field -> ~2 GB
  const ReadResult r = read_all(dir.save("bad_size.aedat4", bytes));
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->byte_offset(), static_cast<std::int64_t>(first_packet)) << r.error->what();
  EXPECT_TRUE(r.events.empty());
}

TEST(IoFormatsCorruption, Aedat4CorruptHeaderIsRejectedAtOpen) {
  const ScratchDir dir("test_io_formats");
  std::vector<std::uint8_t> bytes = load(kAedat4);
  bytes[18 + 0] = 0xFF;  // root table offset of the IOHeader FlatBuffer
  bytes[18 + 1] = 0xFF;
  const ReadResult r = read_all(dir.save("bad_header.aedat4", bytes));
  ASSERT_TRUE(r.error);
  EXPECT_NE(std::string(r.error->what()).find("header"), std::string::npos) << r.error->what();
}

// Random single bit flips (fixed seed): each read must end normally or with
// ReadError — never a crash, a hang or another exception. Run under
// AddressSanitizer to prove the decoders never read out of bounds
// (EVLIFE_BITFLIP_TRIALS=N for more trials per sample than the default 30).
TEST(IoFormatsCorruption, RandomBitFlipsNeverCrash) {
  const ScratchDir dir("test_io_formats");
  std::mt19937_64 rng(20261121);
  const char* env = std::getenv("EVLIFE_BITFLIP_TRIALS");
  const int trials = env != nullptr ? std::max(1, std::atoi(env)) : 30;
  for (const std::string& sample : {kAedat4, kEvt2, kEvt3, kDat}) {
    const std::vector<std::uint8_t> original = load(sample);
    int errors = 0;
    for (int trial = 0; trial < trials; ++trial) {
      std::vector<std::uint8_t> bytes = original;
      // Half the flips in the first 4 KiB (headers), half anywhere.
      const std::size_t range = trial % 2 == 0 ? std::min<std::size_t>(4096, bytes.size()) : bytes.size();
      const std::size_t at = std::uniform_int_distribution<std::size_t>(0, range - 1)(rng);
      bytes[at] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
      const std::string path = dir.save("flip" + fs::path(sample).extension().string(), bytes);
      ReadResult r;
      ASSERT_NO_THROW(r = read_all(path, 1000, /*checked=*/true)) << sample << " flip at " << at;
      errors += r.error.has_value();
    }
    RecordProperty(fs::path(sample).filename().string() + "_errors", errors);
    RecordProperty(fs::path(sample).filename().string() + "_trials", trials);
  }
}

}  // namespace

// ---- Decimal numbers of text files (decimal_number.h) ----

namespace {
struct Parsed {
  bool ok;
  std::int64_t t_us;  // in seconds -> µs
  bool integral;
  bool fraction;      // written_as_fraction
};
Parsed parse_seconds(const std::string& text) {
  evlife::io::detail::DecimalNumber n;
  Parsed p{evlife::io::detail::parse_decimal(text.data(), text.data() + text.size(), n), 0, false, false};
  if (p.ok) {
    p.ok = evlife::io::detail::to_us(n, 1'000'000'000, p.t_us);
    p.integral = n.integral;
    p.fraction = evlife::io::detail::written_as_fraction(n);
  }
  return p;
}
}  // namespace

TEST(IoFormatsDecimal, ExponentsReadExactlyAsTheirPlainSpelling) {
  // Each pair: the same value spelled plainly and with an exponent.
  const std::vector<std::pair<std::string, std::string>> same = {
      {"0.000001", "9.999999999999999547e-07"}, {"0.0015", "1.500000000000000031e-03"},
      {"12", "1.200000000000000000e+01"},       {"1234.5", "1.2345e3"},
      {"-0.25", "-2.5E-1"},                      {"0", "0.000000000000000000e+00"},
      {"1600000000.0012345", "1.6000000000012345e+09"}};
  for (const auto& [plain, exponent] : same) {
    const Parsed a = parse_seconds(plain), b = parse_seconds(exponent);
    ASSERT_TRUE(a.ok && b.ok) << plain << " / " << exponent;
    EXPECT_EQ(a.t_us, b.t_us) << plain << " / " << exponent;
    EXPECT_EQ(a.integral, b.integral) << plain << " / " << exponent;
  }
  EXPECT_EQ(parse_seconds("9.999999999999999547e-07").t_us, 1);
  EXPECT_EQ(parse_seconds("2.2499999e-06").t_us, 2);  // rounded to nearest at the µs
  EXPECT_EQ(parse_seconds("2.5000001e-06").t_us, 3);
  // Integral values with an exponent count as integers (µs columns as savetxt writes them).
  EXPECT_FALSE(parse_seconds("1.500000000000000000e+03").fraction);
  EXPECT_TRUE(parse_seconds("1.5e-03").fraction);
  EXPECT_TRUE(parse_seconds("1500.0").fraction);  // a point without exponent: a fraction, as before
  for (const char* bad : {"", "e5", "1e", "1e+", "1.5e400", "1e40x", "--1", ".", "1.2.3", "1e-41", "nan"})
    EXPECT_FALSE(parse_seconds(bad).ok) << bad;
}

// Every time an event can hold (|t| <= 2^62 us, event.h) reads from text, as
// `convert` writes it in seconds: the conversion went through 64-bit ns and
// refused all past 2^62 ns (~146 years of us, "too large for the time unit").
TEST(IoFormatsDecimal, TimesUpToTheEventRangeReadInSeconds) {
  EXPECT_EQ(parse_seconds("1000000000000.000000").t_us, std::int64_t{1'000'000'000'000'000'000});
  EXPECT_EQ(parse_seconds("4611686018427.387904").t_us, std::int64_t{1} << 62);
  EXPECT_EQ(parse_seconds("-4611686018427.387904").t_us, -(std::int64_t{1} << 62));
  EXPECT_EQ(parse_seconds("4611686018427.3879045").t_us, (std::int64_t{1} << 62) + 1);  // rounded, as below
  // Beyond int64 µs: refused, never wrapped.
  EXPECT_FALSE(parse_seconds("9300000000000").ok);
  EXPECT_FALSE(parse_seconds("18446744073709551615").ok);
}
