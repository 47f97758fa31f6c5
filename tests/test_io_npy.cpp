// NumPy .npy files and .npz archives written by NumPy itself
// (tests/data/npy/make_npy.py): the same 200 events in every layout and type
// users save them in decode to the events the script's formula gives; files
// that are not events are refused with a reason, and faults part-way come
// after the events before them.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "evlife/io/event_reader.h"
#include "read_all.h"

namespace {

using evlife::Event;
namespace io = evlife::io;
using evlife::test::ReadAll;

const std::string kNpy = std::string(EVLIFE_SOURCE_DIR) + "/tests/data/npy/";

/// make_npy.py's events: t = 1000 + 37 i µs, x = i % 50, y = 7 i % 40, ON when i % 3 == 0.
std::vector<Event> expected(int n = 200) {
  std::vector<Event> events;
  for (int i = 0; i < n; ++i) {
    events.push_back(Event{1000 + 37 * i, static_cast<std::uint16_t>(i % 50), static_cast<std::uint16_t>((7 * i) % 40),
                           i % 3 == 0 ? std::int8_t{1} : std::int8_t{-1}});
  }
  return events;
}

void expect_events(const std::vector<Event>& got, const std::vector<Event>& want, const std::string& what) {
  ASSERT_EQ(got.size(), want.size()) << what;
  for (std::size_t i = 0; i < want.size(); ++i) {
    ASSERT_EQ(got[i].t_us, want[i].t_us) << what << " event " << i;
    ASSERT_EQ(got[i].x, want[i].x) << what << " event " << i;
    ASSERT_EQ(got[i].y, want[i].y) << what << " event " << i;
    ASSERT_EQ(got[i].p, want[i].p) << what << " event " << i;
  }
}

TEST(Npy, EveryLayoutAndTypeNumPyWritesReadsAsTheSameEvents) {
  for (const char* name : {"structured_i8", "evlife_read", "seconds_f8", "big_endian", "datetime_ns", "t_ns",
                           "extra_fields", "version2", "version3", "plain_txyp", "plain_xypt_seconds",
                           "plain_xytp"}) {
    const ReadAll r = evlife::test::read_all(kNpy + name + ".npy", {}, 37);
    ASSERT_FALSE(r.error) << name << ": " << r.error->what();
    EXPECT_EQ(r.format, "npy") << name;
    EXPECT_FALSE(r.sensor) << name << ": a .npy states no sensor";
    expect_events(r.events, expected(), name);
  }
}

TEST(Npy, TheTimeUnitGivenOverridesTheRule) {
  io::ReaderOptions ms;
  ms.time_unit = "ms";  // the int64 µs column read as ms: every time x 1000
  const ReadAll r = evlife::test::read_all(kNpy + "structured_i8.npy", ms);
  ASSERT_FALSE(r.error) << r.error->what();
  ASSERT_EQ(r.events.size(), 200u);
  EXPECT_EQ(r.events[1].t_us, 1'037'000);
  io::ReaderOptions bad;
  bad.time_unit = "fortnights";
  EXPECT_NE(evlife::test::open_error(kNpy + "structured_i8.npy", bad).find("unknown time unit 'fortnights'"),
            std::string::npos);
}

TEST(Npy, ArraysThatAreNotEventsAreRefusedWithTheirReason) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"ambiguous", "fit several layouts"},
      {"fortran", "Fortran-ordered"},
      {"five_columns", "an array of shape (200, 5)"},
      {"objects", "'|O' (Python objects"},
      {"no_polarity", "its fields (x, y, t) do not name x, y, t and p"},
  };
  for (const auto& [name, why] : cases) {
    const std::string message = evlife::test::open_error(kNpy + name + ".npy");
    EXPECT_NE(message.find(name + ".npy"), std::string::npos) << message;
    EXPECT_NE(message.find(why), std::string::npos) << name << ": " << message;
  }
}

/// An N x 4 '<i8' .npy of `rows` (NumPy's version 1.0 header, padded to 64 bytes).
std::string save_rows_npy(const std::string& name, const std::vector<std::array<std::int64_t, 4>>& rows) {
  std::string header = "{'descr': '<i8', 'fortran_order': False, 'shape': (" + std::to_string(rows.size()) + ", 4), }";
  header.append(64 - (10 + header.size() + 1) % 64, ' ');
  header += '\n';
  const std::string path = testing::TempDir() + name;
  std::ofstream out(path, std::ios::binary);
  out.write("\x93NUMPY\x01\x00", 8);
  const auto header_bytes = static_cast<std::uint16_t>(header.size());
  out.put(static_cast<char>(header_bytes & 0xff)).put(static_cast<char>(header_bytes >> 8)) << header;
  for (const auto& row : rows) out.write(reinterpret_cast<const char*>(row.data()), sizeof row);  // little-endian host
  return path;
}

// A review helper's finding: a bad value in the first rows (the ones the
// layout is told by) was "no layout fits its first rows" with no row or
// value, where the same fault after them is named with its record.
TEST(Npy, ABadValueInTheFirstRowsIsNamedWithItsRecordForEachLayout) {
  const std::vector<std::pair<std::array<std::int64_t, 4>, std::string>> cases = {
      {{5, 6, 30, 5}, "as x,y,t,p, record 2's column 3 = 5 is not a polarity (1 ON, 0 or -1 OFF)"},
      {{5, 6, 15, 1}, "as x,y,t,p, record 2's column 2 = 15 goes back in time (record 1's is 20)"},
      {{70000, 6, 30, 1}, "as x,y,t,p, record 2's column 0 = 70000 is not x (an integer 0..65535)"},
  };
  for (const auto& [bad, why] : cases) {
    const std::string path = save_rows_npy("bad_first_rows.npy", {{9, 2, 10, 1}, {3, 4, 20, 0}, bad, {7, 8, 40, 1}});
    const std::string message = evlife::test::open_error(path);
    EXPECT_NE(message.find("no layout fits its first rows (as x,y,p,t, record "), std::string::npos) << message;
    EXPECT_NE(message.find(why), std::string::npos) << message;
  }
  // The same rows without the fault read (the writer above is right).
  const std::string good = save_rows_npy("good_first_rows.npy", {{9, 2, 10, 1}, {3, 4, 20, 0}, {5, 6, 30, 1}});
  const ReadAll r = evlife::test::read_all(good);
  EXPECT_FALSE(r.error) << r.error->what();
  EXPECT_EQ(r.events.size(), 3U);
}

TEST(Npy, AFaultPartWayComesAfterTheEventsBeforeIt) {
  {
    const ReadAll r = evlife::test::read_all(kNpy + "cut.npy");
    ASSERT_TRUE(r.error);
    expect_events(r.events, expected(120), "cut");
    EXPECT_EQ(r.error->event_index(), 120);
    EXPECT_NE(std::string(r.error->what()).find("ends inside record 120 of the 200"), std::string::npos)
        << r.error->what();
  }
  {
    const ReadAll r = evlife::test::read_all(kNpy + "bad_x.npy");
    ASSERT_TRUE(r.error);
    expect_events(r.events, expected(50), "bad_x");
    EXPECT_EQ(r.error->event_index(), 50);
    // The header, then 50 records of 4 int64.
    const std::int64_t data_offset = r.error->byte_offset() - 50 * 32;
    EXPECT_GT(data_offset, 0);
    EXPECT_EQ(data_offset % 64, 0) << "numpy aligns the data to 64 bytes";
    EXPECT_NE(std::string(r.error->what()).find("field 'x' = -1 is not a coordinate"), std::string::npos)
        << r.error->what();
  }
  {
    const ReadAll r = evlife::test::read_all(kNpy + "trailing.npy");
    ASSERT_TRUE(r.error);
    expect_events(r.events, expected(), "trailing");
    EXPECT_NE(std::string(r.error->what()).find("5 bytes follow the 200 records"), std::string::npos)
        << r.error->what();
  }
}

TEST(Npy, AFileNamedNpyWithoutItsMagicIsRefusedByTheNpyReader) {
  // Content no format claims: the name decides, and the message says what is missing.
  const std::string junk = ::testing::TempDir() + "/junk.npy";
  {
    std::FILE* f = std::fopen(junk.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    std::fputs("\x01\x02 not an array\n", f);
    std::fclose(f);
  }
  const std::string message = evlife::test::open_error(junk);
  EXPECT_NE(message.find("junk.npy"), std::string::npos) << message;
  EXPECT_NE(message.find("not a readable .npy file: no .npy magic"), std::string::npos) << message;
}

TEST(Npz, AnArrayOfEventsOrOneArrayPerColumnStoredOrCompressedReadsAsTheSameEvents) {
  for (const char* name : {"events", "events_compressed", "columns", "columns_compressed"}) {
    const ReadAll r = evlife::test::read_all(kNpy + name + ".npz", {}, 37);
    ASSERT_FALSE(r.error) << name << ": " << r.error->what();
    EXPECT_EQ(r.format, "npz") << name;
    expect_events(r.events, expected(), name);
  }
  // `evlife info` lists the arrays, the ones read marked.
  const ReadAll one = evlife::test::read_all(kNpy + "events.npz");
  ASSERT_EQ(one.streams.size(), 2u);
  EXPECT_EQ(one.streams[0].name, "events");
  EXPECT_TRUE(one.streams[0].read);
  EXPECT_EQ(one.streams[0].messages, 200u);
  EXPECT_EQ(one.streams[1].name, "labels");
  EXPECT_FALSE(one.streams[1].read);
  const ReadAll columns = evlife::test::read_all(kNpy + "columns.npz");
  ASSERT_EQ(columns.streams.size(), 4u);
  for (const auto& s : columns.streams) EXPECT_TRUE(s.read) << s.name;
}

TEST(Npz, TopicChoosesAmongSeveralArraysOfEvents) {
  EXPECT_NE(evlife::test::open_error(kNpy + "two_event_arrays.npz").find("several arrays of events; --topic NAME "
                                                                         "chooses one (arrays: a (200,), b (50,))"),
            std::string::npos);
  for (const char* topic : {"b", "b.npy"}) {
    io::ReaderOptions b;
    b.topic = topic;
    const ReadAll r = evlife::test::read_all(kNpy + "two_event_arrays.npz", b);
    ASSERT_FALSE(r.error) << r.error->what();
    expect_events(r.events, expected(50), topic);
    ASSERT_EQ(r.streams.size(), 2u);
    EXPECT_FALSE(r.streams[0].read);
    EXPECT_TRUE(r.streams[1].read);
  }
  io::ReaderOptions missing;
  missing.topic = "c";
  EXPECT_NE(evlife::test::open_error(kNpy + "two_event_arrays.npz", missing).find("--topic c: no such array"),
            std::string::npos);
}

TEST(Npz, ArchivesWithoutEventsAreRefusedWithTheirArrays) {
  EXPECT_NE(evlife::test::open_error(kNpy + "no_events.npz").find("no array of events (arrays: image (4, 5))"),
            std::string::npos);
  EXPECT_NE(evlife::test::open_error(kNpy + "unequal_columns.npz").find("no x, y, t and p arrays of one length"),
            std::string::npos);
}

TEST(Npz, ACorruptionOnlyItsChecksumTellsIsAnErrorAfterTheEvents) {
  // A polarity byte changed (ON -> OFF at record 120): every value is plausible, the member's CRC-32 is not.
  const ReadAll r = evlife::test::read_all(kNpy + "crc.npz");
  ASSERT_TRUE(r.error);
  ASSERT_EQ(r.events.size(), 200u);
  EXPECT_EQ(r.events[120].p, -1);
  EXPECT_NE(std::string(r.error->what()).find("its CRC-32 does not match"), std::string::npos) << r.error->what();
}

/// `name` cut to its first `bytes` (patched by `patch`), written beside the test's other files.
std::string cut_copy(const std::string& name, std::size_t bytes,
                     const std::function<void(std::vector<char>&)>& patch = {}) {
  std::ifstream in(kNpy + name, std::ios::binary);
  std::vector<char> data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  data.resize(std::min(bytes, data.size()));
  if (patch) patch(data);
  const std::string path = ::testing::TempDir() + "/cut_" + std::to_string(bytes) + "_" + name;
  std::ofstream(path, std::ios::binary).write(data.data(), static_cast<std::streamsize>(data.size()));
  return path;
}

std::size_t file_bytes(const std::string& name) {
  std::ifstream in(kNpy + name, std::ios::binary | std::ios::ate);
  return static_cast<std::size_t>(in.tellg());
}

TEST(Npz, ACutArchiveGivesTheEventsBeforeTheCutThenAnError) {
  for (const char* name : {"events.npz", "events_compressed.npz"}) {
    // Inside the array: its whole records, then the error at the first it lacks.
    const std::size_t size = file_bytes(name);
    const ReadAll inside = evlife::test::read_all(cut_copy(name, size * 2 / 3));
    ASSERT_TRUE(inside.error) << name;
    ASSERT_GT(inside.events.size(), 20u) << name;
    ASSERT_LT(inside.events.size(), 200u) << name;
    expect_events(inside.events, expected(static_cast<int>(inside.events.size())), name);
    EXPECT_EQ(inside.error->event_index(), static_cast<std::int64_t>(inside.events.size())) << name;
    EXPECT_NE(std::string(inside.error->what()).find("the archive is cut: it ends at byte " + std::to_string(size * 2 / 3)),
              std::string::npos)
        << inside.error->what();
    // Inside the central directory: every event, then the error.
    const ReadAll directory = evlife::test::read_all(cut_copy(name, size - 30));
    ASSERT_TRUE(directory.error) << name;
    expect_events(directory.events, expected(), name);
    EXPECT_NE(std::string(directory.error->what()).find("cut inside its central directory"), std::string::npos)
        << directory.error->what();
  }
  // zipfile states a member's sizes when it closes it: cut while written, its local header says 0
  // (in its ZIP64 extra). The member is read to the cut all the same.
  for (const char* name : {"events.npz", "events_compressed.npz"}) {
    const std::size_t cut_at = file_bytes(name) * 2 / 3;
    const ReadAll stated = evlife::test::read_all(cut_copy(name, cut_at));
    const ReadAll unsized = evlife::test::read_all(cut_copy(name, cut_at, [](std::vector<char>& d) {
      ASSERT_EQ(std::string(d.data() + 30, 10), "events.npy");
      for (std::size_t i = 18; i < 26; ++i) d[i] = '\xff';   // the sizes: in the ZIP64 extra
      for (std::size_t i = 44; i < 60; ++i) d[i] = 0;       // ... which says 0
    }));
    ASSERT_TRUE(unsized.error) << name;
    EXPECT_EQ(unsized.events.size(), stated.events.size()) << name;
    expect_events(unsized.events, expected(static_cast<int>(unsized.events.size())), name);
  }
  // Column arrays: a column cut off is named with the cut.
  const std::string columns = evlife::test::open_error(cut_copy("columns.npz", file_bytes("columns.npz") * 2 / 3));
  EXPECT_NE(columns.find("no x, y, t and p arrays of one length (arrays: x (200,), y (200,), t (200,))"),
            std::string::npos)
      << columns;
  EXPECT_NE(columns.find("a cut archive?): 3 members found by their local headers"), std::string::npos) << columns;
  // Too little for a member: refused, as before.
  EXPECT_NE(evlife::test::open_error(cut_copy("events.npz", 40)).find("no member from its start (a cut local header)"),
            std::string::npos);
}

}  // namespace
