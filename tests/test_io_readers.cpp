// Event readers on the shared real recordings (checked against independent
// decoders: libmatio for .mat, a plain re-decoding in this file for AEDAT 2.0
// and RPG text) and on malformed input: every error must name the file and
// the event index / byte offset, after delivering the events before it.
#include <gtest/gtest.h>
#include <matio.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <optional>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "evlife/io/augmented_event_reader.h"
#include "evlife/io/augmented_event_writer.h"
#include "evlife/io/event_reader.h"
#include "read_all.h"
#include "scratch_dir.h"
#include "evlife/io/sensor_size_from_data.h"

namespace fs = std::filesystem;
using evlife::Event;
using evlife::SensorSize;
using evlife::io::ReadError;

namespace {

const std::string kData = EVLIFE_SHARED_DATA_DIR;
const std::string kStripes = kData + "/reference/stripes.mat";
const std::string kGarfield = kData + "/reference/garfield.mat";
const std::string kAedat2 = kData + "/aedat2/alex_walking_again.aedat";
const std::string kRpg = kData + "/rpg_txt/slider_depth_events_chunk.txt";

using evlife::test::ReadAll;

// As evlife::test::read_all, and an error of opening the file is the result's
// error too (the tests below check both kinds alike).
ReadAll read_all(const std::string& path, const evlife::io::ReaderOptions& options = {},
                 std::size_t batch = 1000) {
  try {
    return evlife::test::read_all(path, options, batch);
  } catch (const ReadError& e) {
    ReadAll r;
    r.error = e;
    return r;
  }
}

std::vector<char> file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  const std::string s = text.str();
  return {s.begin(), s.end()};
}

bool same(const Event& a, const Event& b) {
  return a.t_us == b.t_us && a.x == b.x && a.y == b.y && a.p == b.p;
}

// Reads `path` 1000 events at a time, calling `change` (the file changes
// while being read) after the first read.
ReadAll read_changing_after_the_first_read(const std::string& path, const std::function<void()>& change) {
  ReadAll r;
  try {
    auto reader = evlife::io::open_event_reader(path);
    std::vector<Event> chunk(1000);
    for (std::size_t n = 0, reads = 0; (n = reader->read(chunk)) > 0;) {
      r.events.insert(r.events.end(), chunk.begin(), chunk.begin() + static_cast<std::ptrdiff_t>(n));
      if (++reads == 1) change();
    }
  } catch (const ReadError& e) {
    r.error = e;
  }
  return r;
}

// The file cut to `cut_bytes` after the first read: a recording cut while
// being read (a copy in progress, a full disk). The readers know the size
// they opened.
ReadAll read_cut_after_the_first_read(const std::string& path, std::uintmax_t cut_bytes) {
  return read_changing_after_the_first_read(path, [&] { std::filesystem::resize_file(path, cut_bytes); });
}

// A scratch folder per test, for the tests that write files.
class ScratchFiles : public ::testing::Test {
 protected:
  std::string write(const std::string& name, const std::vector<char>& bytes) const { return dir_.save(name, bytes); }
  std::string write_text(const std::string& name, const std::string& text) const { return dir_.save(name, text); }
  const evlife::test::ScratchDir dir_{std::string("test_io_readers_") +
                                      ::testing::UnitTest::GetInstance()->current_test_info()->name()};
};

// ---------------------------------------------------------------- .mat ----

// The whole `events` variable through libmatio (independent of our reader),
// as events: rows [x y p t], column-major.
std::vector<Event> matio_events(const std::string& path) {
  mat_t* mat = Mat_Open(path.c_str(), MAT_ACC_RDONLY);
  if (mat == nullptr) return {};
  matvar_t* var = Mat_VarRead(mat, "events");
  std::vector<Event> events;
  if (var != nullptr && var->rank == 2 && var->dims[1] == 4) {
    const std::size_t n = var->dims[0];
    auto value = [&](std::size_t row, std::size_t col) -> double {
      const std::size_t k = col * n + row;
      switch (var->class_type) {
        case MAT_C_INT32: return static_cast<const std::int32_t*>(var->data)[k];
        case MAT_C_DOUBLE: return static_cast<const double*>(var->data)[k];
        case MAT_C_INT16: return static_cast<const std::int16_t*>(var->data)[k];
        case MAT_C_SINGLE: return static_cast<double>(static_cast<const float*>(var->data)[k]);
        default: {
          ADD_FAILURE() << "class not handled by the test";
          return 0;
        }
      }
    };
    for (std::size_t i = 0; i < n; ++i) {
      Event e;
      e.x = static_cast<std::uint16_t>(value(i, 0));
      e.y = static_cast<std::uint16_t>(value(i, 1));
      e.p = value(i, 2) > 0 ? 1 : -1;
      e.t_us = static_cast<std::int64_t>(value(i, 3));
      events.push_back(e);
    }
  }
  Mat_VarFree(var);
  Mat_Close(mat);
  return events;
}

void expect_reference_mat(const std::string& path, std::size_t count, double duration_s) {
  const ReadAll r = read_all(path, {}, 4093);  // a batch size that does not divide anything
  ASSERT_FALSE(r.error) << r.error->what();
  EXPECT_EQ(r.format, "mat");
  EXPECT_FALSE(r.sensor);  // the format does not say
  const std::vector<Event> oracle = matio_events(path);
  ASSERT_EQ(oracle.size(), count);
  ASSERT_EQ(r.events.size(), count);
  for (std::size_t i = 0; i < count; ++i)
    ASSERT_TRUE(same(r.events[i], oracle[i])) << "event " << i;
  std::uint16_t max_x = 0, max_y = 0;
  for (std::size_t i = 0; i < count; ++i) {
    max_x = std::max(max_x, r.events[i].x);
    max_y = std::max(max_y, r.events[i].y);
    if (i > 0) {
      ASSERT_LE(r.events[i - 1].t_us, r.events[i].t_us) << i;
    }
  }
  EXPECT_EQ(max_x, 127);  // 0-based DVS128 coordinates, as stored
  EXPECT_EQ(max_y, 127);
  EXPECT_NEAR((r.events.back().t_us - r.events.front().t_us) * 1e-6, duration_s, 0.01);
}

TEST(MatReader, StripesMatchesLibmatioEventByEvent) { expect_reference_mat(kStripes, 340394, 1.20); }
TEST(MatReader, GarfieldMatchesLibmatioEventByEvent) { expect_reference_mat(kGarfield, 202235, 0.74); }

// Writes `events` with libmatio (independent writer) as class/type given.
template <class T>
void matio_write(const std::string& path, const std::vector<Event>& events, matio_classes cls,
                 matio_types type, matio_compression compression, const char* name = "events") {
  std::vector<T> data(events.size() * 4);
  const std::size_t n = events.size();
  for (std::size_t i = 0; i < n; ++i) {
    data[i] = static_cast<T>(events[i].x);
    data[n + i] = static_cast<T>(events[i].y);
    data[2 * n + i] = static_cast<T>(events[i].p);
    data[3 * n + i] = static_cast<T>(events[i].t_us);
  }
  mat_t* mat = Mat_CreateVer(path.c_str(), nullptr, MAT_FT_MAT5);
  ASSERT_NE(mat, nullptr);
  std::size_t dims[2] = {n, 4};
  matvar_t* var = Mat_VarCreate(name, cls, type, 2, dims, data.data(), 0);
  ASSERT_NE(var, nullptr);
  ASSERT_EQ(Mat_VarWrite(mat, var, compression), 0);
  Mat_VarFree(var);
  Mat_Close(mat);
}

std::vector<Event> some_events(std::size_t n, int width = 128, int height = 128) {
  std::vector<Event> events(n);
  std::uint64_t state = 12345;
  std::int64_t t = 1000;
  for (std::size_t i = 0; i < n; ++i) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    t += static_cast<std::int64_t>((state >> 40) % 50);
    events[i].t_us = t;
    events[i].x = static_cast<std::uint16_t>((state >> 20) % static_cast<std::uint64_t>(width));
    events[i].y = static_cast<std::uint16_t>((state >> 8) % static_cast<std::uint64_t>(height));
    events[i].p = (state >> 63) ? 1 : -1;
  }
  return events;
}

class MatFiles : public ScratchFiles {};

TEST_F(MatFiles, ReadsUncompressedAndCompressedDoubleInt16Single) {
  const std::vector<Event> events = some_events(70001);
  std::vector<Event> small = some_events(3);
  for (Event& e : small) e.t_us %= 30000;  // fits int16
  struct Case {
    std::string name;
    const std::vector<Event>* events;
    std::function<void(const std::string&)> write;
  };
  const std::vector<Case> cases = {
      {"double_raw.mat", &events,
       [&](const std::string& p) { matio_write<double>(p, events, MAT_C_DOUBLE, MAT_T_DOUBLE, MAT_COMPRESSION_NONE); }},
      {"double_zlib.mat", &events,
       [&](const std::string& p) { matio_write<double>(p, events, MAT_C_DOUBLE, MAT_T_DOUBLE, MAT_COMPRESSION_ZLIB); }},
      {"single_raw.mat", &small,
       [&](const std::string& p) { matio_write<float>(p, small, MAT_C_SINGLE, MAT_T_SINGLE, MAT_COMPRESSION_NONE); }},
      {"int16_zlib.mat", &small,
       [&](const std::string& p) { matio_write<std::int16_t>(p, small, MAT_C_INT16, MAT_T_INT16, MAT_COMPRESSION_ZLIB); }},
      {"int32_raw.mat", &events,
       [&](const std::string& p) { matio_write<std::int32_t>(p, events, MAT_C_INT32, MAT_T_INT32, MAT_COMPRESSION_NONE); }},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path = dir_.file(c.name);
    c.write(path);
    const ReadAll r = read_all(path, {}, 777);
    ASSERT_FALSE(r.error) << r.error->what();
    ASSERT_EQ(r.events.size(), c.events->size());
    for (std::size_t i = 0; i < r.events.size(); ++i)
      ASSERT_TRUE(same(r.events[i], (*c.events)[i])) << i;
  }
}

// A hand-made uncompressed MAT v5 file: double class stored as miUINT8 /
// miINT16 as MATLAB does when values fit (matio never writes that).
std::vector<char> handmade_mat(std::uint32_t storage_type, const std::vector<std::int64_t>& values,
                               std::size_t rows, std::size_t cols, const std::string& name) {
  std::vector<char> out(128, ' ');
  const std::string text = "MATLAB 5.0 MAT-file, handmade by test_io_readers";
  std::memcpy(out.data(), text.data(), text.size());
  std::memset(out.data() + 116, 0, 8);
  out[124] = 0x00;
  out[125] = 0x01;
  out[126] = 'I';
  out[127] = 'M';
  std::vector<char> body;
  auto u32 = [&](std::uint32_t v) {
    char b[4];
    std::memcpy(b, &v, 4);
    body.insert(body.end(), b, b + 4);
  };
  auto pad = [&] {
    while (body.size() % 8) body.push_back(0);
  };
  u32(6); u32(8); u32(6 /*mxDOUBLE*/); u32(0);                  // array flags
  u32(5); u32(8); u32(static_cast<std::uint32_t>(rows)); u32(static_cast<std::uint32_t>(cols));
  u32(1); u32(static_cast<std::uint32_t>(name.size()));         // name (long format)
  body.insert(body.end(), name.begin(), name.end());
  pad();
  const std::size_t width = storage_type == 2 ? 1 : 2;
  u32(storage_type); u32(static_cast<std::uint32_t>(values.size() * width));
  for (const std::int64_t v : values) {
    if (width == 1) body.push_back(static_cast<char>(static_cast<std::uint8_t>(v)));
    else { const auto s = static_cast<std::int16_t>(v); char b[2]; std::memcpy(b, &s, 2); body.insert(body.end(), b, b + 2); }
  }
  pad();
  std::vector<char> element;
  const std::uint32_t type = 14, bytes = static_cast<std::uint32_t>(body.size());
  element.resize(8);
  std::memcpy(element.data(), &type, 4);
  std::memcpy(element.data() + 4, &bytes, 4);
  out.insert(out.end(), element.begin(), element.end());
  out.insert(out.end(), body.begin(), body.end());
  return out;
}

TEST_F(MatFiles, ReadsDoubleClassStoredAsSmallIntegers) {
  // rows [x y p t]: (3,4,1,10), (5,6,-1,300)
  const std::vector<std::int64_t> column_major = {3, 5, 4, 6, 1, -1, 10, 300};
  const std::string path = write("int16.mat", handmade_mat(3 /*miINT16*/, column_major, 2, 4, "events"));
  const std::vector<Event> oracle = matio_events(path);  // the hand-made file is valid MAT
  ASSERT_EQ(oracle.size(), 2u);
  const ReadAll r = read_all(path);
  ASSERT_FALSE(r.error) << r.error->what();
  ASSERT_EQ(r.events.size(), 2u);
  EXPECT_TRUE(same(r.events[0], oracle[0]));
  EXPECT_TRUE(same(r.events[1], Event{300, 5, 6, -1}));
}

// What follows 'events' must end where the file does, as what precedes it:
// bytes appended (here "GARBAGE"), or a later variable cut, are an input error
// after every event at their offset (they were not looked at: exit 0). A
// whole variable after 'events' is read as before.
TEST_F(MatFiles, BytesAfterTheEventsVariableMustBeWholeElements) {
  const std::vector<Event> events = some_events(5000);
  const std::string two = dir_.file("two.mat");
  matio_write<double>(two, events, MAT_C_DOUBLE, MAT_T_DOUBLE, MAT_COMPRESSION_ZLIB);
  {
    mat_t* mat = Mat_Open(two.c_str(), MAT_ACC_RDWR);
    ASSERT_NE(mat, nullptr);
    std::vector<double> other(300, 1.5);
    std::size_t dims[2] = {300, 1};
    matvar_t* var = Mat_VarCreate("other", MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, other.data(), 0);
    ASSERT_EQ(Mat_VarWrite(mat, var, MAT_COMPRESSION_NONE), 0);
    Mat_VarFree(var);
    Mat_Close(mat);
  }
  const ReadAll whole = read_all(two);
  ASSERT_FALSE(whole.error) << whole.error->what();
  ASSERT_EQ(whole.events.size(), events.size());
  std::ifstream in(two, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const std::string& damaged : {bytes + "GARBAGE", bytes.substr(0, bytes.size() - 100)}) {
    const ReadAll r = read_all(write("damaged.mat", std::vector<char>(damaged.begin(), damaged.end())));
    ASSERT_TRUE(r.error) << damaged.size();
    EXPECT_EQ(r.events.size(), events.size());  // every event first
    EXPECT_EQ(r.error->event_index(), static_cast<std::int64_t>(events.size()));
    EXPECT_NE(std::string(r.error->what()).find("after the variable 'events'"), std::string::npos) << r.error->what();
  }
}

TEST_F(MatFiles, MissingVariableAndWrongShapeAreNamed) {
  const std::string other = write("other.mat", handmade_mat(3, {1, 2, 3, 4}, 1, 4, "evts"));
  ReadAll r = read_all(other);
  ASSERT_TRUE(r.error);
  EXPECT_NE(std::string(r.error->what()).find(other), std::string::npos);
  EXPECT_NE(std::string(r.error->what()).find("no variable 'events'"), std::string::npos);
  EXPECT_NE(std::string(r.error->what()).find("evts"), std::string::npos) << r.error->what();

  const std::string transposed = write("t.mat", handmade_mat(3, {1, 2, 3, 4, 5, 6, 7, 8}, 4, 2, "events"));
  r = read_all(transposed);
  ASSERT_TRUE(r.error);
  EXPECT_NE(std::string(r.error->what()).find("transpose"), std::string::npos) << r.error->what();
}

// A MAT-file cut inside a variable's tag or data, or whose tag is corrupt,
// is named so at the byte offset (a review helper's garfield.mat cut at 132
// bytes said only "no variable 'events' (found: none)", no offset).
TEST_F(MatFiles, ACutOrCorruptVariableTagIsNamedAtItsOffset) {
  const std::vector<char> whole = handmade_mat(3, {1, 2, 3, 4}, 1, 4, "evts");  // one element at 128
  ReadAll r = read_all(write("tag_cut.mat", std::vector<char>(whole.begin(), whole.begin() + 132)));
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->byte_offset(), 128);
  EXPECT_NE(std::string(r.error->what()).find("truncated: a variable's 8-byte tag is cut after 4 bytes"),
            std::string::npos) << r.error->what();
  r = read_all(write("data_cut.mat", std::vector<char>(whole.begin(), whole.end() - 8)));
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->byte_offset(), 128);
  EXPECT_NE(std::string(r.error->what()).find("past the file's end"), std::string::npos) << r.error->what();
  std::vector<char> bad_type = whole;
  bad_type[128] = 0x4e;  // type 78: no MAT type
  r = read_all(write("bad_type.mat", bad_type));
  ASSERT_TRUE(r.error);
  EXPECT_NE(std::string(r.error->what()).find("skipped an element of type 78 at byte offset 128"), std::string::npos)
      << r.error->what();
}

// `events` of two rows [x y p t], column-major doubles, written by matio.
/// A double N×4 `events` (N = column_major.size() / 4) written by libmatio.
void write_rows(const std::string& path, std::vector<double> column_major, matio_compression compression) {
  mat_t* mat = Mat_CreateVer(path.c_str(), nullptr, MAT_FT_MAT5);
  std::size_t dims[2] = {column_major.size() / 4, 4};
  matvar_t* var = Mat_VarCreate("events", MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, column_major.data(), 0);
  Mat_VarWrite(mat, var, compression);
  Mat_VarFree(var);
  Mat_Close(mat);
}

TEST_F(MatFiles, BadPolarityAndNonIntegerCoordinateStopAtTheirRow) {
  // rows: (1,1,1,0) (2,2,5,1) → polarity 5 at index 1
  std::string path = write("pol.mat", handmade_mat(3, {1, 2, 1, 2, 1, 5, 0, 1}, 2, 4, "events"));
  ReadAll r = read_all(path);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.error->event_index(), 1);
  EXPECT_EQ(r.error->path(), path);
  // A double x = 2.5 at row 2 (index 1).
  std::vector<Event> ev = some_events(2);
  path = dir_.file("frac.mat");
  write_rows(path, {1, 2.5, 1, 1, 1, -1, 10, 20}, MAT_COMPRESSION_ZLIB);
  r = read_all(path);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.error->event_index(), 1);
  EXPECT_NE(std::string(r.error->what()).find("x is not"), std::string::npos) << r.error->what();
  // A t past int64 µs (9.3e18) is said to be that: "not a finite integer" named a finite number.
  path = dir_.file("big_t.mat");
  write_rows(path, {1, 2, 1, 2, 1, -1, 10, 9.3e18}, MAT_COMPRESSION_NONE);
  r = read_all(path);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.events.size(), 1u);
  EXPECT_NE(std::string(r.error->what()).find("t is NaN, infinite or beyond +-9.2e18 us"), std::string::npos)
      << r.error->what();
}

// MATLAB users save t in seconds: rounded to µs, every event's time was 0 or
// 1, exit 0. Most of the first 1000 rows' times over 0.001 from a whole
// number make t seconds, whatever the caller's reads; µs computed as seconds
// x 1e6 (float noise) and a corrupt fraction among the first rows stay µs.
TEST_F(MatFiles, TimesInSecondsAreSecondsAndMicrosecondsWithNoiseStayMicroseconds) {
  const std::vector<Event> events = some_events(3000);
  const std::size_t n = events.size();
  const auto columns = [&](auto t_of) {
    std::vector<double> data(4 * n);
    for (std::size_t i = 0; i < n; ++i) {
      data[i] = events[i].x;
      data[n + i] = events[i].y;
      data[2 * n + i] = events[i].p;
      data[3 * n + i] = t_of(i);
    }
    return data;
  };
  const auto save = [&](const std::string& name, std::vector<double> data, matio_compression compression) {
    const std::string path = dir_.file(name);
    write_rows(path, std::move(data), compression);
    return path;
  };
  const std::vector<double> seconds = columns([&](std::size_t i) { return static_cast<double>(events[i].t_us) * 1e-6; });
  // A million events a second from t = 0 (the first 1000 within 1 ms of a whole second): seconds too.
  const std::string fast = save("fast_s.mat", columns([&](std::size_t i) { return static_cast<double>(i) * 1e-6; }),
                                MAT_COMPRESSION_NONE);
  const ReadAll f = read_all(fast);
  ASSERT_FALSE(f.error) << f.error->what();
  ASSERT_EQ(f.events.size(), n);
  for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(f.events[i].t_us, static_cast<std::int64_t>(i)) << i;
  for (const matio_compression compression : {MAT_COMPRESSION_NONE, MAT_COMPRESSION_ZLIB}) {
    const std::string path = save(compression == MAT_COMPRESSION_NONE ? "s_raw.mat" : "s_zlib.mat", seconds, compression);
    for (const std::size_t block : {std::size_t{1}, std::size_t{4096}}) {
      SCOPED_TRACE(path + ", reads of " + std::to_string(block));
      const ReadAll r = read_all(path, {}, block);
      ASSERT_FALSE(r.error) << r.error->what();
      ASSERT_EQ(r.events.size(), n);
      for (std::size_t i = 0; i < n; ++i) ASSERT_TRUE(same(r.events[i], events[i])) << i;
    }
  }
  const std::vector<double> noisy = columns([&](std::size_t i) {
    return static_cast<double>(events[i].t_us) * 1e-6 * 1e6 + (i == 5 ? 0.5 : 0.0);  // one corrupt value too
  });
  std::size_t off_whole = 0;
  for (std::size_t i = 0; i < n; ++i) off_whole += noisy[3 * n + i] != std::floor(noisy[3 * n + i]);
  ASSERT_GT(off_whole, 100u);  // the noise is there
  const ReadAll r = read_all(save("noisy_us.mat", noisy, MAT_COMPRESSION_ZLIB));
  ASSERT_FALSE(r.error) << r.error->what();
  ASSERT_EQ(r.events.size(), n);
  for (std::size_t i = 0; i < n; ++i)
    if (i != 5) {
      ASSERT_TRUE(same(r.events[i], events[i])) << i;
    }
  EXPECT_LE(std::llabs(r.events[5].t_us - events[5].t_us), 1);
}

TEST_F(MatFiles, TruncatedCompressedFileDeliversAnExactPrefixThenNamesTheFile) {
  const std::vector<char> bytes = file_bytes(kGarfield);
  const std::vector<Event> oracle = matio_events(kGarfield);
  for (const double fraction : {0.1, 0.5, 0.9, 0.99999}) {
    SCOPED_TRACE(fraction);
    const auto size = static_cast<std::size_t>(static_cast<double>(bytes.size()) * fraction);
    const std::string path = write("cut.mat", std::vector<char>(bytes.begin(), bytes.begin() + static_cast<long>(size)));
    const ReadAll r = read_all(path);
    ASSERT_TRUE(r.error) << "a truncated file must not read as complete";
    EXPECT_EQ(r.error->path(), path);
    EXPECT_NE(std::string(r.error->what()).find(path), std::string::npos);
    EXPECT_EQ(r.error->event_index(), static_cast<std::int64_t>(r.events.size()));
    ASSERT_LE(r.events.size(), oracle.size());
    for (std::size_t i = 0; i < r.events.size(); ++i) ASSERT_TRUE(same(r.events[i], oracle[i])) << i;
  }
  // Cut inside the 128-byte header / the variable header: error at open.
  for (const std::size_t size : {std::size_t{0}, std::size_t{60}, std::size_t{130}, std::size_t{140}}) {
    const std::string path = write("head.mat", std::vector<char>(bytes.begin(), bytes.begin() + static_cast<long>(size)));
    const ReadAll r = read_all(path);
    ASSERT_TRUE(r.error) << size;
    EXPECT_TRUE(r.events.empty());
    EXPECT_NE(std::string(r.error->what()).find(path), std::string::npos);
  }
}

TEST_F(MatFiles, TruncatedUncompressedFileGivesIndexAndByteOffset) {
  const std::vector<Event> events = some_events(1000);
  const std::string full = dir_.file("full.mat");
  matio_write<std::int32_t>(full, events, MAT_C_INT32, MAT_T_INT32, MAT_COMPRESSION_NONE);
  std::vector<char> bytes = file_bytes(full);
  // t column = last 4000 data bytes (no padding: 16000 bytes of data). Cut 10 t values short.
  bytes.resize(bytes.size() - 40 + 2);
  const std::string path = write("cut.mat", bytes);
  const ReadAll r = read_all(path);
  ASSERT_TRUE(r.error);
  ASSERT_EQ(r.events.size(), 990u);
  for (std::size_t i = 0; i < r.events.size(); ++i) ASSERT_TRUE(same(r.events[i], events[i])) << i;
  EXPECT_EQ(r.error->event_index(), 990);
  // Byte offset of row 990's x value: data start + 990 × 4; data start = file size − 16000.
  const auto data_start = static_cast<std::int64_t>(file_bytes(full).size()) - 16000;
  EXPECT_EQ(r.error->byte_offset(), data_start + 990 * 4);
}

TEST_F(MatFiles, CorruptCompressedDataIsReported) {
  std::vector<char> bytes = file_bytes(kStripes);
  for (const std::size_t at : {bytes.size() / 3, bytes.size() - 6}) {
    std::vector<char> copy = bytes;
    copy[at] = static_cast<char>(copy[at] ^ 0x5A);
    const std::string path = write("corrupt.mat", copy);
    const ReadAll r = read_all(path);
    ASSERT_TRUE(r.error) << "corruption at byte " << at << " went unnoticed";
    EXPECT_EQ(r.error->path(), path);
    EXPECT_EQ(r.error->event_index(), static_cast<std::int64_t>(r.events.size()));
  }
}

// ------------------------------------------------------------- AEDAT 2 ----

TEST(Aedat2Reader, AlexWalkingMatchesIndependentDecoding) {
  const ReadAll r = read_all(kAedat2);
  ASSERT_FALSE(r.error) << r.error->what();
  EXPECT_EQ(r.format, "aedat2");
  ASSERT_TRUE(r.sensor);
  EXPECT_EQ(*r.sensor, (SensorSize{128, 128}));
  ASSERT_EQ(r.events.size(), 19182u);  // PROVENANCE.md
  EXPECT_EQ(r.skipped, 0u);
  // Independent decoding: header length from PROVENANCE.md (4,612 B), then
  // the jAER DVS128 extractor (XMASK 0xfe >> 1 flipped, YMASK 0x7f00 >> 8,
  // raw polarity 0 = ON) with y flipped to a top-left origin.
  const std::vector<char> bytes = file_bytes(kAedat2);
  ASSERT_EQ((bytes.size() - 4612) % 8, 0u);
  auto be32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (int k = 0; k < 4; ++k) v = (v << 8) | static_cast<std::uint8_t>(bytes[at + static_cast<std::size_t>(k)]);
    return v;
  };
  for (std::size_t i = 0; i < r.events.size(); ++i) {
    const std::uint32_t a = be32(4612 + 8 * i), t = be32(4612 + 8 * i + 4);
    const int jaer_x = 127 - static_cast<int>((a & 0xfe) >> 1);
    const int jaer_y = static_cast<int>((a & 0x7f00) >> 8);
    ASSERT_EQ(r.events[i].x, jaer_x) << i;
    ASSERT_EQ(r.events[i].y, 127 - jaer_y) << i;
    ASSERT_EQ(r.events[i].p, (a & 1) == 0 ? 1 : -1) << i;
    ASSERT_EQ(r.events[i].t_us, static_cast<std::int64_t>(t)) << i;
  }
  // First record, decoded by hand: address 0x00007683 → raw x 65, raw y 118, OFF.
  EXPECT_TRUE(same(r.events.front(), Event{41306606, 62, 9, -1}));
  EXPECT_NEAR((r.events.back().t_us - r.events.front().t_us) * 1e-6, 6.89, 0.01);
  for (std::size_t i = 1; i < r.events.size(); ++i) ASSERT_LE(r.events[i - 1].t_us, r.events[i].t_us);
}

class Aedat2Files : public ScratchFiles {
 protected:
  static std::vector<char> header() {
    const std::string h = "#!AER-DAT2.0\r\n# test file\r\n# AEChip: ch.unizh.ini.jaer.chip.retina.DVS128\r\n";
    return {h.begin(), h.end()};
  }
  static void record(std::vector<char>& out, std::uint32_t address, std::uint32_t t) {
    for (const std::uint32_t v : {address, t})
      for (int s = 24; s >= 0; s -= 8) out.push_back(static_cast<char>((v >> s) & 0xFF));
  }
  // Raw address of evlife (x, y top-left, p).
  static std::uint32_t address(int x, int y, int p) {
    return static_cast<std::uint32_t>(((127 - y) << 8) | ((127 - x) << 1) | (p > 0 ? 0 : 1));
  }
};

TEST_F(Aedat2Files, SpecialEventsAreSkippedAndCountedAndClockWrapsUnwrap) {
  std::vector<char> bytes = header();
  record(bytes, address(0, 0, 1), 0xFFFFFF00u);
  record(bytes, 0x8000u, 0xFFFFFF10u);  // special (external) event
  record(bytes, address(127, 127, -1), 0xFFFFFFF0u);
  record(bytes, address(5, 120, 1), 0x00000010u);  // after a 32-bit wrap
  const std::string path = write("wrap.aedat", bytes);
  const ReadAll r = read_all(path);
  ASSERT_FALSE(r.error) << r.error->what();
  ASSERT_EQ(r.events.size(), 3u);
  EXPECT_EQ(r.skipped, 1u);
  EXPECT_TRUE(same(r.events[0], Event{0xFFFFFF00LL, 0, 0, 1}));
  EXPECT_TRUE(same(r.events[1], Event{0xFFFFFFF0LL, 127, 127, -1}));
  EXPECT_TRUE(same(r.events[2], Event{(1LL << 32) + 0x10, 5, 120, 1}));
}

TEST_F(Aedat2Files, ATimestampRisingByMoreThanHalfTheClockIsAStepBackNotAWrap) {
  std::vector<char> bytes = header();
  record(bytes, address(0, 0, 1), 42206000u);
  record(bytes, address(1, 0, 1), 42206537u | 0xFD000000u);  // one corrupt top byte
  record(bytes, address(2, 0, 1), 42207000u);
  const ReadAll r = read_all(write("flip.aedat", bytes));
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.error->event_index(), 1);
  // The message says what else it may be: a gap longer than half the clock.
  EXPECT_NE(std::string(r.error->what()).find("32-bit clock wraps every 71.6 min, so a gap of more than 35.8 min"),
            std::string::npos)
      << r.error->what();
}

TEST_F(Aedat2Files, TruncatedAtEveryByteOfARecord) {
  std::vector<char> full = header();
  const std::size_t header_bytes = full.size();
  for (int i = 0; i < 20; ++i) record(full, address(i, i, 1), static_cast<std::uint32_t>(100 + i));
  for (std::size_t cut = 1; cut < 8; ++cut) {
    SCOPED_TRACE(cut);
    const std::size_t keep = header_bytes + 8 * 12 + cut;  // 12 whole records, then `cut` bytes
    const std::string path = write("cut.aedat", std::vector<char>(full.begin(), full.begin() + static_cast<long>(keep)));
    const ReadAll r = read_all(path, {}, 5);
    ASSERT_TRUE(r.error);
    EXPECT_EQ(r.events.size(), 12u);
    EXPECT_EQ(r.error->path(), path);
    EXPECT_EQ(r.error->event_index(), 12);
    EXPECT_EQ(r.error->byte_offset(), static_cast<std::int64_t>(header_bytes + 8 * 12));
    EXPECT_NE(std::string(r.error->what()).find("truncated"), std::string::npos);
  }
  // Cut inside the header line: error at open.
  const std::string path = write("cuthead.aedat", std::vector<char>(full.begin(), full.begin() + 20));
  const ReadAll r = read_all(path);
  ASSERT_TRUE(r.error);
  EXPECT_NE(std::string(r.error->what()).find(path), std::string::npos);
}

// Cut at a record's end past the reader's first buffer: the whole records
// before the cut, then an error (a quiet end of file before).
TEST_F(Aedat2Files, AFileCutWhileBeingReadEndsInAnErrorAfterItsEvents) {
  std::vector<char> bytes = header();
  const std::size_t header_bytes = bytes.size();
  for (int i = 0; i < 200'000; ++i) record(bytes, address(i % 128, (i / 128) % 128, 1), static_cast<std::uint32_t>(i));
  const std::size_t kept = 100'000;  // records; the reader buffers 65,536 at a time
  const ReadAll r = read_cut_after_the_first_read(write("cut.aedat", bytes), header_bytes + 8 * kept);
  ASSERT_TRUE(r.error) << "the cut passed for the end of the file (" << r.events.size() << " events)";
  EXPECT_NE(std::string(r.error->what()).find("cut while being read"), std::string::npos) << r.error->what();
  EXPECT_EQ(r.error->byte_offset(), static_cast<std::int64_t>(header_bytes + 8 * kept)) << r.error->what();
  ASSERT_EQ(r.events.size(), kept);
  EXPECT_EQ(r.events.back().t_us, static_cast<std::int64_t>(kept - 1));
}

TEST_F(Aedat2Files, CorruptAddressAndBackwardTimestampGiveIndexAndOffset) {
  std::vector<char> good = header();
  const std::size_t h = good.size();
  for (int i = 0; i < 10; ++i) record(good, address(i, 2 * i, 1), static_cast<std::uint32_t>(1000 + 10 * i));
  {
    std::vector<char> bytes = good;
    bytes[h + 8 * 6] = 0x7F;  // top address byte of record 6: impossible for a DVS128
    const std::string path = write("corrupt.aedat", bytes);
    const ReadAll r = read_all(path, {}, 4);
    ASSERT_TRUE(r.error);
    EXPECT_EQ(r.events.size(), 6u);
    EXPECT_EQ(r.error->event_index(), 6);
    EXPECT_EQ(r.error->byte_offset(), static_cast<std::int64_t>(h + 8 * 6));
  }
  {
    std::vector<char> bytes = header();
    for (int i = 0; i < 10; ++i) {
      if (i == 3) record(bytes, 0x8000u, 1025u);  // a special event shifts the offsets
      record(bytes, address(i, 0, -1), static_cast<std::uint32_t>(i == 7 ? 500 : 1000 + 10 * i));
    }
    const std::string path = write("back.aedat", bytes);
    const ReadAll r = read_all(path, {}, 1000);
    ASSERT_TRUE(r.error);
    EXPECT_EQ(r.events.size(), 7u);
    EXPECT_EQ(r.error->event_index(), 7);
    EXPECT_EQ(r.error->byte_offset(), static_cast<std::int64_t>(h + 8 * 8));  // 7 events + 1 special
    EXPECT_NE(std::string(r.error->what()).find("backwards"), std::string::npos);
    EXPECT_NE(std::string(r.error->what()).find(path), std::string::npos);
  }
}

TEST_F(Aedat2Files, OtherChipsAreRefusedByName) {
  // (DAVIS chips are read: test_io_aedat2_davis.cpp; CDAVIS has an address layout of its own.)
  std::string h = "#!AER-DAT2.0\r\n# AEChip: eu.seebetter.ini.chips.davis.CDAVIS\r\n";
  const std::string path = write_text("cdavis.aedat", h);
  const ReadAll r = read_all(path);
  ASSERT_TRUE(r.error);
  EXPECT_NE(std::string(r.error->what()).find("CDAVIS"), std::string::npos);
}

// ------------------------------------------------------------ RPG text ----

TEST(RpgTextReader, SliderDepthMatchesIndependentDecoding) {
  const ReadAll r = read_all(kRpg, {}, 999);
  ASSERT_FALSE(r.error) << r.error->what();
  EXPECT_EQ(r.format, "rpg-text");
  EXPECT_FALSE(r.sensor);
  ASSERT_EQ(r.events.size(), 50000u);
  // Independent: the seconds as text with the point removed = nanoseconds
  // (9 decimals in this file), rounded to µs.
  std::ifstream in(kRpg);
  std::string t_text;
  int x = 0, y = 0, p = 0;
  std::size_t i = 0;
  while (in >> t_text >> x >> y >> p) {
    const std::size_t dot = t_text.find('.');
    ASSERT_EQ(t_text.size() - dot - 1, 9u);
    const long long ns = std::stoll(t_text.substr(0, dot) + t_text.substr(dot + 1));
    ASSERT_LT(i, r.events.size());
    ASSERT_EQ(r.events[i].t_us, (ns + 500) / 1000) << i;
    ASSERT_EQ(r.events[i].x, x);
    ASSERT_EQ(r.events[i].y, y);
    ASSERT_EQ(r.events[i].p, p == 1 ? 1 : -1);
    ++i;
  }
  EXPECT_EQ(i, 50000u);
  for (std::size_t k = 1; k < r.events.size(); ++k) ASSERT_LE(r.events[k - 1].t_us, r.events[k].t_us);
  EXPECT_NEAR((r.events.back().t_us - r.events.front().t_us) * 1e-6, 0.17, 0.01);
}

class RpgFiles : public ScratchFiles {};

TEST_F(RpgFiles, CommentsBlankLinesCrlfSensorLineAndExactRounding) {
  const std::string path = write_text("a.txt",
      "# comment\r\n"
      "\r\n"
      "240 180\r\n"
      "0.000001 1 2 1\r\n"
      "   # indented comment\n"
      "1.0000004 3 4 0\n"
      "1.0000005\t5\t6\t1\n"
      "123456.999999 239 179 0\n"
      "4000000000.1 0 0 1");  // no final newline; > 2^32 µs
  const ReadAll r = read_all(path);
  ASSERT_FALSE(r.error) << r.error->what();
  ASSERT_TRUE(r.sensor);
  EXPECT_EQ(*r.sensor, (SensorSize{240, 180}));
  ASSERT_EQ(r.events.size(), 5u);
  EXPECT_TRUE(same(r.events[0], Event{1, 1, 2, 1}));
  EXPECT_TRUE(same(r.events[1], Event{1000000, 3, 4, -1}));
  EXPECT_TRUE(same(r.events[2], Event{1000001, 5, 6, 1}));
  EXPECT_TRUE(same(r.events[3], Event{123456999999LL, 239, 179, -1}));
  EXPECT_TRUE(same(r.events[4], Event{4000000000100000LL, 0, 0, 1}));
}

TEST_F(RpgFiles, AFileCutWhileBeingReadEndsInAnErrorAfterItsEvents) {
  std::string text;
  std::size_t cut = 0, lines_kept = 0;
  for (int i = 0; i < 150'000; ++i) {
    text += std::to_string(i) + "e-6 " + std::to_string(i % 128) + " " + std::to_string((i / 128) % 128) + " 1\n";
    if (text.size() <= (std::size_t{3} << 19)) {  // 1.5 MiB: past the reader's 1 MiB buffer
      cut = text.size();
      lines_kept = static_cast<std::size_t>(i) + 1;
    }
  }
  ASSERT_LT(cut, text.size());
  const ReadAll r = read_cut_after_the_first_read(write_text("cut.txt", text), cut);
  ASSERT_TRUE(r.error) << "the cut passed for the end of the file (" << r.events.size() << " events)";
  EXPECT_NE(std::string(r.error->what()).find("cut while being read"), std::string::npos) << r.error->what();
  EXPECT_EQ(r.events.size(), lines_kept);
}

// Another, smaller file renamed over the path while the first is read (a
// recorder or rsync replacing it): the opened file is read whole, no cut said
// (the size was taken by name: "cut while being read", exit 3).
TEST_F(RpgFiles, AFileRenamedOverThePathWhileReadIsNoCut) {
  std::string text;
  for (int i = 0; i < 150'000; ++i) text += std::to_string(i) + "e-6 " + std::to_string(i % 128) + " 5 1\n";
  const std::string path = write_text("replaced.txt", text);
  const std::string other = write_text("other.txt", "0.5 1 1 1\n");
  const ReadAll r = read_changing_after_the_first_read(path, [&] { std::filesystem::rename(other, path); });
  EXPECT_FALSE(r.error) << r.error->what();
  EXPECT_EQ(r.events.size(), 150'000u);
}

TEST_F(RpgFiles, BadLineStopsWithLineOffsetAndIndex) {
  const std::string good = "0.1 1 1 1\n0.2 2 2 0\n";
  for (const char* bad : {"0.3 3 3 2\n", "0.3 3\n", "0.3 x 3 1\n", "0.3 3 3 1 9\n",
                                 "0.3 70000 3 1\n", "0.3 3 3"}) {
    SCOPED_TRACE(bad);
    const std::string path = write_text("bad.txt", good + std::string(bad) + "0.4 4 4 1\n");
    const ReadAll r = read_all(path);
    ASSERT_TRUE(r.error);
    EXPECT_EQ(r.events.size(), 2u);
    EXPECT_EQ(r.error->event_index(), 2);
    EXPECT_EQ(r.error->byte_offset(), static_cast<std::int64_t>(good.size()));
    EXPECT_NE(std::string(r.error->what()).find("line 3"), std::string::npos) << r.error->what();
    EXPECT_NE(std::string(r.error->what()).find(path), std::string::npos);
  }
}

// A line longer than the reader's 1 MiB buffer stops the file there.
TEST_F(RpgFiles, LineLongerThanTheBufferStopsAtItsOffset) {
  const std::string head = "0.1 1 1 1\n";
  const std::string path = write_text("long.txt", head + "0.2 2 2 " + std::string(2 << 20, '1') + "\n");
  const ReadAll r = read_all(path);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.error->event_index(), 1);
  EXPECT_EQ(r.error->byte_offset(), static_cast<std::int64_t>(head.size()));
  EXPECT_NE(std::string(r.error->what()).find("line 2: expected 't x y p' (t seconds, x y integers, p 0 or 1), "
                                              "got '(line longer than 1048576 bytes)'"),
            std::string::npos)
      << r.error->what();
}

TEST_F(RpgFiles, CoordinateOutsideTheSensorAndTimeGoingBackwards) {
  const std::string text = "0.1 1 1 1\n0.2 99 2 0\n0.3 100 5 1\n0.4 4 4 1\n";
  const std::string path = write_text("out.txt", text);
  evlife::io::ReaderOptions options;
  options.sensor = SensorSize{100, 100};
  ReadAll r = read_all(path, options);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.events.size(), 2u);
  EXPECT_EQ(r.error->event_index(), 2);
  EXPECT_EQ(r.error->byte_offset(), 21);  // start of line 3
  EXPECT_NE(std::string(r.error->what()).find("outside"), std::string::npos) << r.error->what();

  const std::string stated = write_text("stated.txt", "50 40\n0.1 49 39 1\n0.2 10 40 1\n");
  r = read_all(stated);  // sensor stated by the file
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.error->event_index(), 1);

  const std::string back = write_text("back.txt", "0.1 1 1 1\n0.3 2 2 1\n0.2 3 3 1\n");
  r = read_all(back, {}, 1);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.events.size(), 2u);
  EXPECT_EQ(r.error->event_index(), 2);
  EXPECT_EQ(r.error->byte_offset(), 20);
  EXPECT_NE(std::string(r.error->what()).find("backwards"), std::string::npos);
  evlife::io::ReaderOptions unordered;
  unordered.require_time_order = false;
  EXPECT_FALSE(read_all(back, unordered).error);
}

// ------------------------------------------------------- open / sniffing ----

class Sniffing : public ScratchFiles {};

TEST_F(Sniffing, MissingFileIsNamed) {
  const std::string path = dir_.file("does_not_exist.aedat");
  const ReadAll r = read_all(path);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->path(), path);
  EXPECT_NE(std::string(r.error->what()).find(path), std::string::npos);
  EXPECT_NE(std::string(r.error->what()).find("No such file"), std::string::npos);
  EXPECT_THROW(evlife::io::open_event_reader(dir_.path().string()), ReadError);  // a directory
}

TEST_F(Sniffing, UnknownFormatListsKnownOnes) {
  const std::string path = write("noise.xyz", std::vector<char>{'\x01', '\x02', '\xff', '\x00', 'z'});
  const ReadAll r = read_all(path);
  ASSERT_TRUE(r.error);
  const std::string what = r.error->what();
  EXPECT_NE(what.find(path), std::string::npos);
  EXPECT_NE(what.find("unknown"), std::string::npos);
  for (const auto& f : evlife::io::known_event_formats())
    EXPECT_NE(what.find(std::string(f.name)), std::string::npos) << f.name;
  for (const char* name : {"mat", "aedat2", "rpg-text"})
    EXPECT_NE(what.find(name), std::string::npos) << name;
  EXPECT_TRUE(read_all(write("empty.bin", {})).error);
}

TEST_F(Sniffing, FormatComesFromContentNotName) {
  // An AEDAT 2.0 file named .txt and a text file named .dat are still recognised.
  const std::vector<char> aedat = file_bytes(kAedat2);
  EXPECT_EQ(read_all(write("really_aedat.txt", aedat)).format, "aedat2");
  EXPECT_EQ(read_all(write_text("events.data", "0.5 1 2 1\n")).format, "rpg-text");
  const std::vector<char> mat = file_bytes(kGarfield);
  EXPECT_EQ(read_all(write("m.bin", mat)).format, "mat");
}

TEST(SensorSize, FromFormatUserOrData) {
  using evlife::io::SensorSizeSource;
  auto r = evlife::io::resolve_sensor_size(kAedat2, SensorSize{10, 10});
  EXPECT_EQ(r.source, SensorSizeSource::format);
  EXPECT_EQ(r.size, (SensorSize{128, 128}));
  r = evlife::io::resolve_sensor_size(kRpg, SensorSize{320, 240});
  EXPECT_EQ(r.source, SensorSizeSource::user);
  EXPECT_EQ(r.size, (SensorSize{320, 240}));
  r = evlife::io::resolve_sensor_size(kRpg, std::nullopt);
  EXPECT_EQ(r.source, SensorSizeSource::data);
  EXPECT_EQ(r.size, (SensorSize{240, 180}));  // DAVIS240C, per PROVENANCE.md
  EXPECT_EQ(evlife::io::sensor_size_from_data(kStripes), (SensorSize{128, 128}));
}

// One rule for a size from the data: a fault after some events ends the scan
// (the processing pass reports it after those events); no event is an error.
// Augmented files: the stated size, else the same max + 1 rule.
class SensorSizeFiles : public ScratchFiles {};
TEST_F(SensorSizeFiles, FromDataStopsAtAFaultAndAugmentedFilesFollowTheSameRule) {
  const std::string faulty = write_text("faulty.txt", "0.1 5 7 1\n0.2 9 3 0\n0.3 x 1 1\n0.4 50 60 1\n");
  const ReadAll all = read_all(faulty);
  EXPECT_TRUE(all.error.has_value());  // the file really is faulty, after 2 events
  EXPECT_EQ(all.events.size(), 2u);
  EXPECT_EQ(evlife::io::sensor_size_from_data(faulty), (SensorSize{10, 8}));
  EXPECT_THROW(evlife::io::sensor_size_from_data(write_text("bad.txt", "0.1 x 1 1\n")), evlife::io::ReadError);

  const std::vector<evlife::AugmentedEvent> events{
      {evlife::Event{10, 3, 4, 1}, 500.0f, 1.0f, 0.0f}, {evlife::Event{20, 11, 2, -1}, 0.0f, 0.0f, 0.0f}};
  for (const char* name : {"a.csv", "a.bin"}) {
    const std::string path = dir_.file(name);
    auto writer = evlife::io::open_augmented_writer(path, SensorSize{64, 48});
    writer->write(events);
    writer->close();
    const SensorSize expected = std::string(name) == "a.bin" ? SensorSize{64, 48}   // stated in the header
                                                             : SensorSize{12, 5};  // max x + 1, max y + 1
    EXPECT_EQ(evlife::io::sensor_size_of_augmented(path), expected) << name;
    // --sensor: the size of a file that states none (a stated one wins, as for a recording).
    EXPECT_EQ(evlife::io::sensor_size_of_augmented(path, SensorSize{7, 7}),
              (std::string(name) == "a.bin" ? SensorSize{64, 48} : SensorSize{7, 7})) << name;
  }
  // A side beyond any camera's, stated (a corrupt header) or spanned (a stray
  // coordinate): an error naming the file and the way around it, not a plane
  // of gigabytes for the caller; --sensor still reads the file.
  const std::vector<evlife::AugmentedEvent> stray{{evlife::Event{10, 3, 4, 1}, 0.0f, 0.0f, 0.0f},
                                                  {evlife::Event{20, 2, 59999, -1}, 0.0f, 0.0f, 0.0f}};
  for (const auto& [name, stated, written] :
       {std::tuple{"huge.bin", SensorSize{60000, 60000}, events}, std::tuple{"stray.csv", SensorSize{64, 48}, stray}}) {
    const std::string path = dir_.file(name);
    auto writer = evlife::io::open_augmented_writer(path, stated);
    writer->write(written);
    writer->close();
    try {
      (void)evlife::io::sensor_size_of_augmented(path);
      ADD_FAILURE() << name << ": no error";
    } catch (const evlife::io::ReadError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("x60000, more than any camera (at most 4096 px a side): give --sensor"),
                std::string::npos)
          << e.what();
    }
    EXPECT_EQ(evlife::io::sensor_size_of_augmented(path, SensorSize{64, 48}), (SensorSize{64, 48})) << name;
  }
}

}  // namespace

namespace {

// The batch size must not change what is read (state carried across calls).
TEST(Readers, ResultDoesNotDependOnBatchSize) {
  for (const std::string& path : {kGarfield, kAedat2, kRpg}) {
    SCOPED_TRACE(path);
    const ReadAll big = read_all(path, {}, 65536);
    const ReadAll small = read_all(path, {}, 7);
    ASSERT_FALSE(big.error);
    ASSERT_FALSE(small.error);
    ASSERT_EQ(big.events.size(), small.events.size());
    for (std::size_t i = 0; i < big.events.size(); ++i) ASSERT_TRUE(same(big.events[i], small.events[i])) << i;
  }
}

TEST(Readers, ProgressReachesTheFileSize) {
  for (const std::string& path : {kStripes, kAedat2, kRpg}) {
    auto reader = evlife::io::open_event_reader(path);
    std::vector<Event> buffer(4096);
    EXPECT_LT(reader->bytes_consumed(), fs::file_size(path));
    while (reader->read(buffer) != 0) {
    }
    EXPECT_EQ(reader->bytes_consumed(), fs::file_size(path)) << path;
  }
}

}  // namespace

namespace {

class RealFilesCut : public ScratchFiles {};

// Cutting a real recording anywhere gives an exact prefix of its events and,
// unless the cut falls on a record boundary, an error at the next index.
TEST_F(RealFilesCut, AnyCutGivesAnExactPrefix) {
  for (const std::string& source : {kAedat2, kRpg}) {
    const ReadAll whole = read_all(source);
    ASSERT_FALSE(whole.error);
    const std::vector<char> bytes = file_bytes(source);
    for (const double fraction : {0.37, 0.5, 0.81, 0.999}) {
      for (const std::size_t nudge : {std::size_t{0}, std::size_t{3}, std::size_t{5}}) {
        const std::size_t size = static_cast<std::size_t>(static_cast<double>(bytes.size()) * fraction) + nudge;
        SCOPED_TRACE(source + " cut at " + std::to_string(size));
        const std::string path = write("cut", std::vector<char>(bytes.begin(), bytes.begin() + static_cast<long>(size)));
        const ReadAll r = read_all(path, {}, 500);
        ASSERT_LE(r.events.size(), whole.events.size());
        ASSERT_GT(r.events.size(), 0u);
        // (A text line cut inside t, x or y leaves fewer than 4 fields: an
        // error, never a different event.)
        for (std::size_t i = 0; i < r.events.size(); ++i) ASSERT_TRUE(same(r.events[i], whole.events[i])) << i;
        if (r.error) {
          EXPECT_EQ(r.error->event_index(), static_cast<std::int64_t>(r.events.size()));
          EXPECT_EQ(r.error->path(), path);
          EXPECT_GE(r.error->byte_offset(), 0);
        } else if (source == kAedat2) {
          ADD_FAILURE() << "a cut inside an 8-byte record went unnoticed";
        }
      }
    }
  }
}

}  // namespace

namespace {

// A corrupt line quoted into the error: a NUL would end the message early for
// printf (losing the event index and offset), a stray byte fail Python's UTF-8
// decoding (a UnicodeDecodeError instead of the InputError). Both are written
// as \xNN; the message's own UTF-8 and the path stay as they are.
TEST(ReadErrors, BytesQuotedFromACorruptFileArePrintable) {
  const evlife::test::ScratchDir dir("test_io_readers");
  const std::string path = dir.file("bytes_µs.txt");
  std::ofstream(path, std::ios::binary) << std::string("0.1 1 1 1\n0.2 1 \xff 1\0\0\n", 22);
  const ReadAll r = read_all(path);
  ASSERT_TRUE(r.error);
  const std::string message = r.error->what();
  EXPECT_EQ(r.events.size(), 1u);
  EXPECT_EQ(message.find('\0'), std::string::npos);
  EXPECT_NE(message.find("got '0.2 1 \\xff 1\\x00\\x00'"), std::string::npos) << message;
  EXPECT_NE(message.find(path), std::string::npos) << message;
  EXPECT_NE(message.find("(event index 1, byte offset 10)"), std::string::npos) << message;
  EXPECT_EQ(r.error->path(), path);
}

}  // namespace

namespace {

// A stop signal during the scan for a sensor size (process of a long file
// that states none) ends it at once with what it has, so that the command
// can write an output of no event and exit 130; without a stop, every event.
TEST(SensorSizeScan, AStopEndsTheScanAfterTheEventsReadSoFar) {
  const evlife::test::ScratchDir dir("test_io_readers");
  const std::string path = dir.file("late_far_event.txt");
  {
    std::ofstream out(path);
    for (int i = 0; i < 70'000; ++i) out << 1e-6 * i << " " << i % 10 << " " << i % 7 << " 1\n";
    out << "0.1 200 150 0\n";  // beyond the scan's first 65536 events
  }
  const std::atomic<bool> go_on{false}, stop{true};
  EXPECT_EQ(evlife::io::sensor_size_from_data(path, {}, &go_on), (SensorSize{201, 151}));
  EXPECT_EQ(evlife::io::sensor_size_from_data(path), (SensorSize{201, 151}));
  EXPECT_EQ(evlife::io::sensor_size_from_data(path, {}, &stop), (SensorSize{10, 7}));
  // The rule every command uses passes the stop on (`run` ended by the signal, unsaid, before).
  EXPECT_EQ(evlife::io::resolve_sensor_size(path, std::nullopt, {}, &stop).size, (SensorSize{10, 7}));
  EXPECT_EQ(evlife::io::resolve_sensor_size(path, std::nullopt, {}, &go_on).size, (SensorSize{201, 151}));
}

}  // namespace
