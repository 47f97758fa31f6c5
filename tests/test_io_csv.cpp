// CSV / text layouts of other tools (io/formats/src/csv_text_reader.cpp): each layout,
// separator, header or not, time unit from header / values / --time-unit,
// faults, and a CSV written by `evlife convert` read back.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "evlife/io/event_reader.h"
#include "read_all.h"
#include "scratch_dir.h"

namespace {

using evlife::Event;
namespace io = evlife::io;
using evlife::test::ReadAll;
using evlife::test::ScratchDir;

ReadAll read_all(const std::string& path, const std::string& time_unit = {}) {
  io::ReaderOptions options;
  options.time_unit = time_unit;
  return evlife::test::read_all(path, options, 7);
}

bool same(const std::vector<Event>& a, const std::vector<Event>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].t_us != b[i].t_us || a[i].x != b[i].x || a[i].y != b[i].y || a[i].p != b[i].p) return false;
  }
  return true;
}

// The same three events in every layout: (t µs, x, y, p).
const std::vector<Event> kExpected = {{1000, 10, 20, 1}, {1500, 11, 21, -1}, {2250, 639, 479, 1}};

TEST(IoCsv, MetavisionXypt) {
  const ScratchDir dir("test_io_csv");
  const ReadAll r = read_all(dir.save("mv.csv", "10,20,1,1000\n11,21,0,1500\n639,479,1,2250\n"));
  ASSERT_FALSE(r.error) << r.error->what();
  EXPECT_EQ(r.format, "csv");
  EXPECT_TRUE(same(r.events, kExpected));
}

// A line whose first byte became '#' (or '%') was dropped as a comment,
// uncounted (39 of 40 events, exit 0). Comment lines after the first event
// are now counted and shown as skipped records; those before it (a header's
// notes, as Metavision writes) are not.
TEST(IoCsv, CommentLinesAmongTheEventsAreCountedAsSkipped) {
  const ScratchDir dir("test_io_csv");
  const ReadAll before = read_all(dir.save("notes.csv", "# recorded 2026\n%% by me\n10,20,1,1000\n11,21,0,1500\n\n639,479,1,2250\n"));
  ASSERT_FALSE(before.error) << before.error->what();
  EXPECT_TRUE(same(before.events, kExpected));
  EXPECT_EQ(before.skipped, 0u);
  const ReadAll among = read_all(dir.save("hash.csv", "10,20,1,1000\n#1,21,0,1500\n11,21,0,1500\n%39,479,1,2250\n639,479,1,2250\n"));
  ASSERT_FALSE(among.error) << among.error->what();
  EXPECT_TRUE(same(among.events, kExpected));
  EXPECT_EQ(among.skipped, 2u);
  const ReadAll rpg = read_all(dir.save("hash.txt", "0.001000 10 20 1\n#.001500 11 21 0\n0.002250 639 479 1\n"));
  ASSERT_FALSE(rpg.error) << rpg.error->what();
  EXPECT_EQ(rpg.format, "rpg-text");
  EXPECT_EQ(rpg.events.size(), 2u);
  EXPECT_EQ(rpg.skipped, 1u);
}

TEST(IoCsv, XytpWithHeaderTabSeparated) {
  const ScratchDir dir("test_io_csv");
  const ReadAll r = read_all(dir.save("a.tsv", "x\ty\tt\tp\n10\t20\t1000\t1\n11\t21\t1500\t0\n639\t479\t2250\t1\n"));
  ASSERT_FALSE(r.error) << r.error->what();
  EXPECT_TRUE(same(r.events, kExpected));
}

TEST(IoCsv, TxypSecondsFromHeaderAndFromValues) {
  const ScratchDir dir("test_io_csv");
  // Header with a unit, space separated, any extension.
  const ReadAll a = read_all(dir.save("a.dat.txt", "timestamp(s) x y polarity\n0.001 10 20 1\n0.0015 11 21 -1\n0.00225 639 479 1\n"));
  ASSERT_FALSE(a.error) << a.error->what();
  EXPECT_EQ(a.format, "csv");
  EXPECT_TRUE(same(a.events, kExpected));
  // No header, comma separated: the decimal point says seconds.
  const ReadAll b = read_all(dir.save("b.csv", "0.001000,10,20,1\n0.001500,11,21,0\n0.002250,639,479,1\n"));
  ASSERT_FALSE(b.error) << b.error->what();
  EXPECT_TRUE(same(b.events, kExpected));
  // Header naming µs, integer values.
  const ReadAll c = read_all(dir.save("c.csv", "t_us,x,y,p\n1000,10,20,1\n1500,11,21,0\n2250,639,479,1\n"));
  ASSERT_FALSE(c.error) << c.error->what();
  EXPECT_TRUE(same(c.events, kExpected));
}

TEST(IoCsv, TimeUnitOptionOverrides) {
  const ScratchDir dir("test_io_csv");
  const ReadAll r = read_all(dir.save("ms.csv", "x,y,p,t\n10,20,1,1\n11,21,0,1.5\n639,479,1,2.25\n"), "ms");
  ASSERT_FALSE(r.error) << r.error->what();
  EXPECT_TRUE(same(r.events, kExpected));
  const ReadAll ns = read_all(dir.save("ns.csv", "10,20,1,1000000\n11,21,0,1500000\n639,479,1,2250000\n"), "ns");
  ASSERT_FALSE(ns.error) << ns.error->what();
  EXPECT_TRUE(same(ns.events, kExpected));
  // Epoch nanoseconds (19 digits), as ROS tools export them.
  const ReadAll epoch = read_all(dir.save("epoch.csv", "10,20,1,1600000000001000000\n11,21,0,1600000000001500000\n"
                                                       "639,479,1,1600000000002250000\n"),
                                 "ns");
  ASSERT_FALSE(epoch.error) << epoch.error->what();
  ASSERT_EQ(epoch.events.size(), kExpected.size());
  for (std::size_t i = 0; i < kExpected.size(); ++i) {
    EXPECT_EQ(epoch.events[i].t_us, 1'600'000'000'000'000 + kExpected[i].t_us);
  }
}

// Without a unit the first lines' times tell it: whole -> µs. A fraction
// after them was rounded to µs, silently (or, with fewer whole lines first,
// made the whole file seconds): now an input error that asks for the unit.
TEST(IoCsv, AFractionAfterTheWholeTimesThatMadeTheUnitUsAsksForTheUnit) {
  const ScratchDir dir("test_io_csv");
  std::string text = "x,y,t,p\n";
  for (int i = 0; i < 1500; ++i) text += "1,1," + std::to_string(i) + ",1\n";  // past the lines sampled
  text += "1,1,1500.5,0\n";
  const std::string path = dir.save("whole_then_fraction.csv", text);
  const ReadAll r = read_all(path);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.events.size(), 1500u);
  EXPECT_EQ(r.error->event_index(), 1500);
  EXPECT_NE(std::string(r.error->what()).find("line 1502: '1,1,1500.5,0': its t is a fraction, but the whole times "
                                              "of the first lines made the unit µs"),
            std::string::npos)
      << r.error->what();
  // Said in seconds or µs, it reads.
  const ReadAll s = read_all(path, "s");
  ASSERT_FALSE(s.error) << s.error->what();
  EXPECT_EQ(s.events.back().t_us, 1'500'500'000);
  const ReadAll us = read_all(path, "us");
  ASSERT_FALSE(us.error) << us.error->what();
  EXPECT_EQ(us.events.back().t_us, 1501);  // rounded to nearest, as the unit was given
}

// NumPy's savetxt writes every column as "%.18e" by default: times in seconds
// as 9.999999999999999547e-07, coordinates as 1.000000000000000000e+00.
std::string savetxt(const std::vector<std::vector<double>>& rows, const char* sep, const char* header = "") {
  std::string text = header;
  char buf[64];
  for (const auto& row : rows) {
    for (std::size_t i = 0; i < row.size(); ++i) {
      std::snprintf(buf, sizeof buf, "%.18e", row[i]);
      text += (i == 0 ? "" : sep) + std::string(buf);
    }
    text += "\n";
  }
  return text;
}

TEST(IoCsv, NumpySavetxtDefaultFormatReads) {
  const ScratchDir dir("test_io_csv");
  const std::vector<std::vector<double>> txyp_s = {{0.001, 10, 20, 1}, {0.0015, 11, 21, 0}, {0.00225, 639, 479, 1}};
  // Space separated t x y p in seconds (the rpg-text reader), with and without a header.
  for (const char* header : {"", "t x y p\n"}) {
    const ReadAll r = read_all(dir.save("s.txt", savetxt(txyp_s, " ", header)));
    ASSERT_FALSE(r.error) << header << r.error->what();
    EXPECT_TRUE(same(r.events, kExpected)) << header;
  }
  // Comma separated, t,x,y,p with a header, and x,y,p,t without one: t in µs
  // as integral values ("1.000000000000000000e+03") stays µs.
  const ReadAll h = read_all(dir.save("h.csv", savetxt(txyp_s, ",", "t,x,y,p\n")));
  ASSERT_FALSE(h.error) << h.error->what();
  EXPECT_TRUE(same(h.events, kExpected));
  const ReadAll us = read_all(dir.save("us.csv", savetxt({{10, 20, 1, 1000}, {11, 21, 0, 1500}, {639, 479, 1, 2250}}, ",")));
  ASSERT_FALSE(us.error) << us.error->what();
  EXPECT_TRUE(same(us.events, kExpected));
  // A fractional coordinate is not a pixel: refused, naming its line.
  const ReadAll frac = read_all(dir.save("frac.txt", savetxt({{0.001, 10, 20, 1}, {0.0015, 11.5, 21, 0}}, " ")));
  ASSERT_TRUE(frac.error);
  EXPECT_EQ(frac.events.size(), 1u);
  EXPECT_NE(std::string(frac.error->what()).find("line 2"), std::string::npos) << frac.error->what();
}

TEST(IoCsv, ATimeGoingBackwardsNamesItsLinesByteOffset) {
  const ScratchDir dir("test_io_csv");
  const std::string text = "x,y,p,t\n1,2,1,100\n3,4,0,200\n5,6,1,150\n";
  const ReadAll r = read_all(dir.save("back.csv", text));
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.events.size(), 2u);
  EXPECT_EQ(r.error->event_index(), 2);
  EXPECT_EQ(r.error->byte_offset(), static_cast<std::int64_t>(text.find("5,6,1,150")));
}

// Excel's "CSV UTF-8", PowerShell and Notepad start the file with a UTF-8
// byte-order mark: it is no part of the header's first name, nor of the first
// number; byte offsets stay the file's.
TEST(IoCsv, AByteOrderMarkBeforeTheFirstLineIsSkipped) {
  const ScratchDir dir("test_io_csv");
  const std::string bom = "\xEF\xBB\xBF";
  const ReadAll header = read_all(dir.save("excel.csv", bom + "x,y,t,p\r\n10,20,1000,1\r\n11,21,1500,0\r\n639,479,2250,1\r\n"));
  ASSERT_FALSE(header.error) << header.error->what();
  EXPECT_EQ(header.format, "csv");
  EXPECT_TRUE(same(header.events, kExpected));
  // No header, named .txt: found by content, so the sniffer must skip the mark too.
  const ReadAll metavision = read_all(dir.save("mv.txt", bom + "10,20,1,1000\n11,21,0,1500\n639,479,1,2250\n"));
  ASSERT_FALSE(metavision.error) << metavision.error->what();
  EXPECT_EQ(metavision.format, "csv");
  EXPECT_TRUE(same(metavision.events, kExpected));
  const ReadAll rpg = read_all(dir.save("rpg.dat", bom + "0.001 10 20 1\n0.0015 11 21 0\n0.00225 639 479 1\n"));
  ASSERT_FALSE(rpg.error) << rpg.error->what();
  EXPECT_EQ(rpg.format, "rpg-text");
  EXPECT_TRUE(same(rpg.events, kExpected));
  const std::string text = bom + "x,y,p,t\n1,2,1,100\n3,4,0,200\n5,6,1,150\n";
  const ReadAll back = read_all(dir.save("back.csv", text));
  ASSERT_TRUE(back.error);
  EXPECT_EQ(back.events.size(), 2u);
  EXPECT_EQ(back.error->byte_offset(), static_cast<std::int64_t>(text.find("5,6,1,150")));
}

TEST(IoCsv, SpaceSeparatedSecondsStayRpgText) {
  const ReadAll r = read_all(std::string(EVLIFE_SHARED_DATA_DIR) + "/rpg_txt/slider_depth_events_chunk.txt");
  ASSERT_FALSE(r.error);
  EXPECT_EQ(r.format, "rpg-text");
  EXPECT_EQ(r.events.size(), 50'000u);
}

TEST(IoCsv, UnreadableFileNamesTheLayouts) {
  const ScratchDir dir("test_io_csv");
  for (const std::string text : {"a,b,c,d\n1,2,3,4\n", "1,2,3\n4,5,6\n", "5,5,5,5\n"}) {
    try {
      (void)read_all(dir.save("bad.csv", text));
      ADD_FAILURE() << text;
    } catch (const io::ReadError& e) {
      EXPECT_NE(std::string(e.what()).find("x,y,p,t (metavision_file_to_csv), x,y,t,p or t,x,y,p"),
                std::string::npos)
          << e.what();
    }
  }
}

// A review helper's finding: a bad value in the first lines (the ones the
// layout is told by) was "no accepted layout fits the first lines" with no
// line or value, where the same fault after them is named with its line.
TEST(IoCsv, ABadValueInTheFirstLinesIsNamedWithItsLineForEachLayout) {
  const ScratchDir dir("test_io_csv");
  const std::string text = "# x,y,t,p\n1,2,10,1\n3,4,20,0\n5,6,30,5\n7,8,40,1\n";
  try {
    (void)read_all(dir.save("bad_p.csv", text));
    ADD_FAILURE() << "read";
  } catch (const io::ReadError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("no accepted layout fits the first lines (as x,y,p,t, line 2's field 3 = 10 is not a polarity "
                     "(1 ON, 0 or -1 OFF); as x,y,t,p, line 4's field 4 = 5 is not a polarity (1 ON, 0 or -1 OFF); "
                     "as t,x,y,p, line 4's field 4 = 5 is not a polarity (1 ON, 0 or -1 OFF))"),
              std::string::npos)
        << m;
  }
  try {
    (void)read_all(dir.save("back.csv", "1,2,10,1\n3,4,20.5,0\n5,6,15,1\n"));
    ADD_FAILURE() << "read";
  } catch (const io::ReadError& e) {
    EXPECT_NE(std::string(e.what()).find("as x,y,t,p, line 3's field 3 = 15 goes back in time (line 2's is 20.5)"),
              std::string::npos)
        << e.what();
  }
  // A review helper's finding: a time beyond int64 µs when compared as seconds counted as 0, "goes back in
  // time (line 1's is 5)", and the file was refused. It is no step back: integer times are µs, and it reads.
  const ReadAll r = read_all(dir.save("huge.csv", "1,2,5,1\n1,2,99999999999999,0\n1,2,99999999999999,0\n"));
  EXPECT_FALSE(r.error) << r.error->what();
  ASSERT_EQ(r.events.size(), 3U);
  EXPECT_EQ(r.events[1].t_us, 99999999999999);
}

TEST(IoCsv, BadLineStopsWithItsLineEventsBeforeKept) {
  const ScratchDir dir("test_io_csv");
  const std::string path = dir.save("cut.csv", "x,y,t,p\n10,20,1000,1\n11,21,1500,0\n639,479,22x0,1\n1,1,3000,1\n");
  const ReadAll r = read_all(path);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.events.size(), 2u);
  const std::string what = r.error->what();
  EXPECT_NE(what.find("line 4"), std::string::npos) << what;
  EXPECT_NE(what.find(path), std::string::npos) << what;
  EXPECT_EQ(r.error->event_index(), 2);
  EXPECT_EQ(r.error->byte_offset(), 8 + 13 + 13);  // the lines before
}

// A review helper's finding: a file whose only line (an event, or the header
// alone) lacked the final '\n' was "not a readable CSV/text event file: no
// event line found" (RPG text without a .txt name: "unknown event file
// format"): the layout was told from whole lines only, the file's last taken
// for cut. It reads as with the '\n'; a row cut short is still named.
TEST(IoCsv, AFilesLastLineWithoutNewlineReadsAsWithIt) {
  const ScratchDir dir("test_io_csv");
  struct Case {
    const char* name;  // .data: told by content, not by the name
    std::string text;
    const char* format;
    std::size_t events;
  };
  for (const Case& c : {Case{"one.csv", "10,20,1,1000", "csv", 1}, Case{"header.csv", "x,y,t,p", "csv", 0},
                        Case{"one.data", "10,20,1,1000", "csv", 1}, Case{"header.data", "x,y,t,p", "csv", 0},
                        Case{"two.csv", "10,20,1,1000\n11,21,0,1500", "csv", 2},
                        // t,x,y,p: the first line alone fits x,y,t,p too; the last tells them apart.
                        Case{"txyp.csv", "0,292,281,0\n100,41,136,1", "csv", 2},
                        Case{"xytp.csv", "283,102,100,1\n182,212,105,1", "csv", 2},
                        Case{"rpg.data", "0.000001 1 1 1", "rpg-text", 1}}) {
    for (const std::string& text : {c.text, c.text + "\n"}) {
      const ReadAll r = read_all(dir.save(c.name, text));
      EXPECT_FALSE(r.error) << text << ": " << r.error->what();
      EXPECT_EQ(r.format, c.format) << text;
      EXPECT_EQ(r.events.size(), c.events) << text;
    }
  }
  const ReadAll one = read_all(dir.save("one.csv", "10,20,1,1000"));
  ASSERT_EQ(one.events.size(), 1U);
  EXPECT_TRUE(same(one.events, {{1000, 10, 20, 1}}));
  // A cut row: refused as before, with its line and offset.
  const ReadAll cut = read_all(dir.save("cut.csv", "x,y,t,p\n1,2,10,1\n3,4,2"));
  ASSERT_TRUE(cut.error);
  EXPECT_EQ(cut.events.size(), 1U);
  EXPECT_EQ(cut.error->byte_offset(), 17);
  EXPECT_NE(std::string(cut.error->what()).find("line 3: expected 4 fields 'x,y,t,p'"), std::string::npos)
      << cut.error->what();
  EXPECT_NE(evlife::test::open_error(dir.save("cut_only.csv", "1,2,1")).find("a line has 3 fields, not 4"),
            std::string::npos);
  // A Metavision x,y,p,t file cut inside its last time: that line (126 after
  // 1259) told the layout too, none fitted, and the file was refused with
  // none of its events (a shift hunt's finding). Now the lines before it tell
  // the layout, they are read, and the cut line is the error.
  const ReadAll cut_time = read_all(dir.save("cut_time.csv", "19,94,1,1000\n50,275,1,1007\n424,105,0,1014\n136,278,1,126"));
  ASSERT_TRUE(cut_time.error);
  EXPECT_EQ(cut_time.events.size(), 3U);
  EXPECT_EQ(cut_time.error->event_index(), 3);
  EXPECT_NE(std::string(cut_time.error->what()).find("timestamp goes backwards"), std::string::npos)
      << cut_time.error->what();
}

// A line longer than the reader's 1 MiB buffer stops the file there, the
// events before it kept.
TEST(IoCsv, LineLongerThanTheBufferStopsAtItsOffset) {
  const ScratchDir dir("test_io_csv");
  const std::string head = "x,y,t,p\n10,20,1000,1\n";
  const std::string path = dir.save("long.csv", head + "11,21," + std::string(2 << 20, '5') + ",1\n");
  const ReadAll r = read_all(path);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.error->event_index(), 1);
  EXPECT_EQ(r.error->byte_offset(), static_cast<std::int64_t>(head.size()));
  EXPECT_NE(std::string(r.error->what()).find("line 3: expected 4 fields"), std::string::npos) << r.error->what();
  EXPECT_NE(std::string(r.error->what()).find("got '(line longer than 1048576 bytes)'"), std::string::npos)
      << r.error->what();
}

// evlife's own CSV (process -> .bin, convert .bin -> .csv) reads back as the
// recording's events (the x, y, t, p columns; the others are ignored).
TEST(IoCsv, CsvWrittenByEvlifeConvertReadsBack) {
  const ScratchDir dir("test_io_csv");
  const std::string input = std::string(EVLIFE_SHARED_DATA_DIR) + "/aedat2/alex_walking_again.aedat";
  const auto run = [&](const std::string& args) {
    return evlife::test::run_cli(EVLIFE_CLI_PATH, args, dir.file("cli.log"));
  };
  const auto processed = run("process '" + input + "' -q -o '" + dir.file("a.bin") + "'");
  ASSERT_EQ(processed.exit_code, 0) << processed.output;
  const auto converted = run("convert '" + dir.file("a.bin") + "' '" + dir.file("a.csv") + "' -q");
  ASSERT_EQ(converted.exit_code, 0) << converted.output;
  const ReadAll original = read_all(input);
  const ReadAll back = read_all(dir.file("a.csv"));
  ASSERT_FALSE(back.error) << back.error->what();
  EXPECT_EQ(back.format, "csv");
  ASSERT_EQ(back.events.size(), 19'182u);
  EXPECT_TRUE(same(back.events, original.events));
  // And a CSV of another tool converts to RPG text.
  const std::string mv = dir.save("mv.csv", "10,20,1,1000\n11,21,0,1500\n639,479,1,2250\n");
  const auto to_txt = run("convert '" + mv + "' '" + dir.file("mv.txt") + "' -q");
  ASSERT_EQ(to_txt.exit_code, 0) << to_txt.output;
  const ReadAll txt = read_all(dir.file("mv.txt"));
  EXPECT_TRUE(same(txt.events, kExpected));
}

}  // namespace
