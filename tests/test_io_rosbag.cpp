// ROS 2 bags (sqlite3 storage): the three shared bags of ros-event-camera's
// event_camera_codecs reproduce the checksums that repository's own tests
// assert (../shared/data/PROVENANCE.md, "ROS bags"); bags written here by an
// independent test-side CDR writer (dvs_msgs / prophesee_event_msgs); topic
// choice; faults (events before them kept, file + message index named).
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <zstd.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <span>
#include <string>
#include <tuple>
#include <vector>

#include "cli_runner.h"
#include "evlife/io/event_reader.h"
#include "evlife/io/stop.h"
#include "read_all.h"
#include "ros2_bag_reference.h"
#include "ros_messages.h"
#include "rosbag2_messages.h"
#include "scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using evlife::Event;
using evlife::SensorSize;
namespace io = evlife::io;
namespace ros = evlife::io::ros;
using evlife::test::decode_db3;
using evlife::test::kRosBagSums;
using evlife::test::ros_sums;
using evlife::test::RosMessages;
using evlife::test::RosSums;

const std::string kData = std::string(EVLIFE_SHARED_DATA_DIR) + "/rosbag";
const std::string kEvt3Bag = kData + "/test_data_evt3_trigger";
const std::string kLibcaerBag = kData + "/test_data_libcaer_rollover";
const std::string kMonoBag = kData + "/test_data_mono_cd";

struct TriggerSums final : io::Evt3TriggerSink {
  std::uint64_t count = 0, t_ns = 0, edge = 0, id = 0;
  void on_trigger(std::int64_t t_us, int e, int i) override {
    ++count;
    t_ns += static_cast<std::uint64_t>(t_us) * 1000u;
    edge += static_cast<std::uint64_t>(e);
    id += static_cast<std::uint64_t>(i);
  }
};

TEST(Rosbag2Checksums, Evt3WithTriggers) {
  TriggerSums triggers;
  const RosMessages r = decode_db3(kEvt3Bag, &triggers);
  EXPECT_EQ(r.size(), 105u);
  EXPECT_EQ(ros_sums(r), kRosBagSums.at("evt3"));
  EXPECT_EQ(triggers.count, 2u);
  EXPECT_EQ(triggers.t_ns, 29096982000u);
  EXPECT_EQ(triggers.edge, 1u);
  EXPECT_EQ(triggers.id, 0u);
}

TEST(Rosbag2Checksums, LibcaerWithClockRollover) {
  const RosMessages r = decode_db3(kLibcaerBag);
  EXPECT_EQ(r.size(), 201u);
  EXPECT_EQ(ros_sums(r), kRosBagSums.at("libcaer"));
  // libcaer_summarize, first message: first/last time, OFF and ON counts.
  const std::vector<ros::RosEvent>& first = r.at(0);
  ASSERT_EQ(first.size(), 1613u);
  EXPECT_EQ(first.front().t_ns, 1702309120762236018);
  EXPECT_EQ(first.back().t_ns, 1702309120772213018);
  std::size_t on = 0;
  for (const ros::RosEvent& e : first) on += e.p > 0 ? 1u : 0u;
  EXPECT_EQ(on, 872u);
  EXPECT_EQ(first.size() - on, 741u);
  // libcaer_find_first: the second message's first time.
  EXPECT_EQ(r.at(1).front().t_ns, 1702309120772229018);
}

TEST(Rosbag2Checksums, Mono) {
  const RosMessages r = decode_db3(kMonoBag);
  EXPECT_EQ(r.size(), 2u);
  EXPECT_EQ(ros_sums(r), kRosBagSums.at("mono"));
}

namespace {

// One libcaer polarity event: valid mark (bit 0), polarity, y, x; 31-bit µs.
std::vector<std::uint8_t> libcaer_word(std::uint32_t x, std::uint32_t y, std::uint32_t p, std::int32_t ts,
                                       std::uint32_t valid = 1) {
  std::vector<std::uint8_t> b(8);
  const std::uint32_t data = (x << 17) | (y << 2) | (p << 1) | valid;
  std::memcpy(b.data(), &data, 4);
  std::memcpy(b.data() + 4, &ts, 4);
  return b;
}

std::vector<std::uint8_t> libcaer_payload(std::initializer_list<std::vector<std::uint8_t>> words) {
  std::vector<std::uint8_t> payload;
  for (const auto& w : words) payload.insert(payload.end(), w.begin(), w.end());
  return payload;
}

}  // namespace

// The shared libcaer bag wraps its clock between messages (time_base moves);
// a wrap inside one message is added here: + 2^31 µs when ts drops by more
// than half the clock's range.
TEST(RosPayloads, LibcaerClockWrapInsideAMessage) {
  const auto payload = libcaer_payload({libcaer_word(3, 4, 1, 2'147'483'000), libcaer_word(5, 6, 0, 100),
                                        libcaer_word(7, 8, 1, 200)});
  std::vector<ros::RosEvent> out;
  std::uint64_t invalid = 0;
  ASSERT_FALSE(ros::decode_libcaer(payload, 5000, 640, 480, out, invalid));
  ASSERT_EQ(out.size(), 3u);
  const std::int64_t wrap_ns = (std::int64_t{1} << 31) * 1000;
  EXPECT_EQ(out[0].t_ns, 5000 + std::int64_t{2'147'483'000} * 1000);
  EXPECT_EQ(out[1].t_ns, 5000 + wrap_ns + 100'000);
  EXPECT_EQ(out[2].t_ns, 5000 + wrap_ns + 200'000);
  EXPECT_EQ(out[1].x, 5);
  EXPECT_EQ(out[1].y, 6);
  EXPECT_EQ(out[1].p, -1);
  EXPECT_EQ(invalid, 0u);
  // Outside the stated sensor: the events before are kept, the fault names the byte.
  out.clear();
  const auto fault = ros::decode_libcaer(payload, 0, 5, 480, out, invalid);
  ASSERT_TRUE(fault);
  EXPECT_EQ(fault->byte_in_message, 8u);
  EXPECT_EQ(out.size(), 1u);
}

// A small drop of the clock is no wrap: the event keeps its earlier time, for
// the checked reader to report as a step back (it was put 35.8 min later,
// silently: a corrupt timestamp, or the zeroed bytes of a cut database).
// Events without libcaer's valid mark are skipped and counted.
TEST(RosPayloads, LibcaerStepBackIsNoWrapAndInvalidEventsAreCounted) {
  const auto payload = libcaer_payload({libcaer_word(3, 4, 1, 5'000'000), libcaer_word(5, 6, 0, 4'995'000),
                                        libcaer_word(0, 0, 0, 0, /*valid=*/0), libcaer_word(7, 8, 1, 5'000'100)});
  std::vector<ros::RosEvent> out;
  std::uint64_t invalid = 0;
  ASSERT_FALSE(ros::decode_libcaer(payload, 1000, 640, 480, out, invalid));
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out[0].t_ns, 1000 + std::int64_t{5'000'000} * 1000);
  EXPECT_EQ(out[1].t_ns, 1000 + std::int64_t{4'995'000} * 1000);
  EXPECT_EQ(out[2].t_ns, 1000 + std::int64_t{5'000'100} * 1000);
  EXPECT_EQ(out[2].x, 7);
  EXPECT_EQ(invalid, 1u);
}

// EVT 3.0 in bags: the decoder state (time, row) carries over message borders.
TEST(RosPayloads, Evt3StateCarriesAcrossMessages) {
  const std::vector<std::uint16_t> words = {0x8001, 0x6002, 0x0007, 0x2805, 0x6003, 0x2006};
  std::vector<std::uint8_t> bytes(words.size() * 2);
  std::memcpy(bytes.data(), words.data(), bytes.size());
  io::Evt3Decoder decoder;
  std::vector<Event> scratch;
  std::vector<ros::RosEvent> all;
  std::vector<ros::RosEvent> out;
  for (const std::size_t cut : {0u, 3u}) {  // two messages: words 0-2, 3-5
    const std::span<const std::uint8_t> part(bytes.data() + cut * 2, 6);
    out.clear();
    ASSERT_FALSE(ros::decode_evt3(part, decoder, scratch, out));
    all.insert(all.end(), out.begin(), out.end());
  }
  ASSERT_EQ(all.size(), 2u);
  EXPECT_EQ(all[0].t_ns, ((1 << 12) | 2) * 1000);
  EXPECT_EQ(all[0].x, 5);
  EXPECT_EQ(all[0].y, 7);
  EXPECT_EQ(all[0].p, 1);
  EXPECT_EQ(all[1].t_ns, ((1 << 12) | 3) * 1000);
  EXPECT_EQ(all[1].y, 7);
  EXPECT_EQ(all[1].p, -1);
}

// Two zero words in a row (zero-filled data: no encoder sets row 0 twice with
// nothing between) are a fault at the first, within a message or across two.
TEST(RosPayloads, Evt3ZeroWordsInARowAreAFaultAtTheFirst) {
  const auto decode = [](io::Evt3Decoder& decoder, const std::vector<std::uint16_t>& words) {
    std::vector<std::uint8_t> bytes(words.size() * 2);
    std::memcpy(bytes.data(), words.data(), bytes.size());
    std::vector<Event> scratch;
    std::vector<ros::RosEvent> out;
    return std::pair{ros::decode_evt3(bytes, decoder, scratch, out), out.size()};
  };
  io::Evt3Decoder one;
  const auto [fault, events] = decode(one, {0x8001, 0x0003, 0x2004, 0x0000, 0x0000, 0x2005});
  ASSERT_TRUE(fault);
  EXPECT_EQ(fault->byte_in_message, 6u);
  EXPECT_NE(fault->what.find("zero-filled"), std::string::npos) << fault->what;
  EXPECT_EQ(events, 1u);
  io::Evt3Decoder two;
  ASSERT_FALSE(decode(two, {0x8001, 0x0003, 0x2004, 0x0000}).first);
  const auto [next, none] = decode(two, {0x0000, 0x2005});
  ASSERT_TRUE(next);
  EXPECT_EQ(next->byte_in_message, 0u);  // the first is in the message before
  EXPECT_EQ(none, 0u);
}

// ---- through open_event_reader, as every command reads ----

using evlife::test::ReadAll;

ReadAll read_all(const std::string& path, const std::string& topic = {}) {
  io::ReaderOptions options;
  options.topic = topic;
  return evlife::test::read_all(path, options, 1000);
}

// The checksums but Σt (µs here, not ns).
RosSums sums_xyp(const std::vector<Event>& events) {
  RosSums s;
  for (const Event& e : events) {
    s.x += e.x;
    s.y += e.y;
    s.p += e.p > 0 ? 1u : 0u;
  }
  s.events = events.size();
  return s;
}

RosSums without_t(RosSums s) {
  s.t = 0;
  return s;
}

TEST(Rosbag2Reader, FolderAndDb3FileReadAlike) {
  const ReadAll folder = read_all(kEvt3Bag);
  ASSERT_FALSE(folder.error) << folder.error->what();
  EXPECT_EQ(folder.format, "rosbag2");
  EXPECT_EQ(folder.sensor, (SensorSize{1280, 720}));
  EXPECT_EQ(sums_xyp(folder.events), without_t(kRosBagSums.at("evt3")));
  // Skipped: 2 triggers + the OTHERS / CONTINUED words (PROVENANCE.md word counts).
  EXPECT_EQ(folder.skipped, 2u + 15688u + 12512u + 25024u);
  const ReadAll file = read_all(kEvt3Bag + "/test_data_evt3_trigger_0.db3");
  ASSERT_FALSE(file.error);
  ASSERT_EQ(file.events.size(), folder.events.size());
  EXPECT_EQ(0, std::memcmp(file.events.data(), folder.events.data(), folder.events.size() * sizeof(Event)));
}

TEST(Rosbag2Reader, LibcaerAndMonoTimesFlooredToMicroseconds) {
  const ReadAll caer = read_all(kLibcaerBag);
  ASSERT_FALSE(caer.error) << caer.error->what();
  EXPECT_EQ(caer.sensor, (SensorSize{640, 480}));
  EXPECT_EQ(sums_xyp(caer.events), without_t(kRosBagSums.at("libcaer")));
  EXPECT_EQ(caer.events.front().t_us, 1702309120762236);  // ...762236018 ns
  const ReadAll mono = read_all(kMonoBag);
  ASSERT_FALSE(mono.error) << mono.error->what();
  EXPECT_EQ(mono.sensor, (SensorSize{640, 480}));
  ASSERT_EQ(mono.events.size(), 100u);
  // Message 2 (time_base 50000 ns): event i = 50 + k at x 320 + k, dt = 1000 k.
  EXPECT_EQ(mono.events[51].t_us, 51);
  EXPECT_EQ(mono.events[51].x, 321);
}

// ---- bags written here (independent CDR writer, sqlite3 directly) ----

using evlife::test::ScratchDir;

void exec(sqlite3* db, const std::string& sql) {
  char* err = nullptr;
  ASSERT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &err), SQLITE_OK) << (err ? err : "");
}

struct Db {
  sqlite3* db = nullptr;
  explicit Db(const std::string& path) { EXPECT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK); }
  ~Db() { sqlite3_close(db); }
  void insert(int id, int topic, std::int64_t t, const std::vector<std::uint8_t>& data) {
    sqlite3_stmt* s = nullptr;
    ASSERT_EQ(sqlite3_prepare_v2(db, "INSERT INTO messages VALUES (?1, ?2, ?3, ?4)", -1, &s, nullptr), SQLITE_OK);
    sqlite3_bind_int(s, 1, id);
    sqlite3_bind_int(s, 2, topic);
    sqlite3_bind_int64(s, 3, t);
    sqlite3_bind_blob(s, 4, data.data(), static_cast<int>(data.size()), SQLITE_TRANSIENT);
    EXPECT_EQ(sqlite3_step(s), SQLITE_DONE);
    sqlite3_finalize(s);
  }
};

void create_tables(sqlite3* db) {
  exec(db,
       "CREATE TABLE topics(id INTEGER PRIMARY KEY,name TEXT NOT NULL,type TEXT NOT NULL,"
       "serialization_format TEXT NOT NULL,offered_qos_profiles TEXT NOT NULL);"
       "CREATE TABLE messages(id INTEGER PRIMARY KEY,topic_id INTEGER NOT NULL,"
       "timestamp INTEGER NOT NULL, data BLOB NOT NULL);");
}

/// Little-endian CDR writer: each primitive aligned to its size from the
/// byte after the 4-byte encapsulation header.
class CdrWriter {
 public:
  CdrWriter() : bytes_{0, 1, 0, 0} {}
  template <typename T>
  void put(T v) {
    while ((bytes_.size() - 4) % sizeof(T) != 0) bytes_.push_back(0);
    const auto* p = reinterpret_cast<const std::uint8_t*>(&v);
    bytes_.insert(bytes_.end(), p, p + sizeof(T));
  }
  void put_string(const std::string& s) {
    put(static_cast<std::uint32_t>(s.size() + 1));
    bytes_.insert(bytes_.end(), s.begin(), s.end());
    bytes_.push_back(0);
  }
  const std::vector<std::uint8_t>& bytes() const { return bytes_; }

 private:
  std::vector<std::uint8_t> bytes_;
};

/// dvs_msgs/EventArray (= prophesee_event_msgs/EventArray) of `events`.
std::vector<std::uint8_t> event_array(const std::vector<ros::RosEvent>& events, std::uint32_t width,
                                      std::uint32_t height) {
  CdrWriter w;
  w.put<std::int32_t>(1);
  w.put<std::uint32_t>(2);
  w.put_string("cam");
  w.put(height);
  w.put(width);
  w.put(static_cast<std::uint32_t>(events.size()));
  for (const ros::RosEvent& e : events) {
    w.put(e.x);
    w.put(e.y);
    w.put(static_cast<std::int32_t>(e.t_ns / 1'000'000'000));
    w.put(static_cast<std::uint32_t>(e.t_ns % 1'000'000'000));
    w.put(static_cast<std::uint8_t>(e.p > 0 ? 1 : 0));
  }
  return w.bytes();
}

TEST(Rosbag2Reader, DvsAndPropheseeArraysDecodeToTheMonoBagEvents) {
  // The mono bag's events, re-encoded as per-event stamps, must read back the same.
  const RosMessages mono = decode_db3(kMonoBag);
  const ReadAll reference = read_all(kMonoBag);
  ASSERT_FALSE(reference.error);
  const ScratchDir dir{"test_io_rosbag"};
  for (const std::string type : {"dvs_msgs/msg/EventArray", "prophesee_event_msgs/msg/EventArray"}) {
    const std::string path = dir.file(type.substr(0, type.find('/')) + ".db3");
    {
      Db db(path);
      create_tables(db.db);
      exec(db.db, "INSERT INTO topics VALUES (1, '/events', '" + type + "', 'cdr', '')");
      exec(db.db, "INSERT INTO topics VALUES (2, '/imu', 'sensor_msgs/msg/Imu', 'cdr', '')");
      for (std::size_t i = 0; i < mono.size(); ++i)
        db.insert(static_cast<int>(i + 1), 1, static_cast<std::int64_t>(i), event_array(mono[i], 640, 480));
    }
    const ReadAll r = read_all(path);
    ASSERT_FALSE(r.error) << r.error->what();
    EXPECT_EQ(r.sensor, (SensorSize{640, 480}));
    ASSERT_EQ(r.events.size(), reference.events.size());
    EXPECT_EQ(0, std::memcmp(r.events.data(), reference.events.data(), r.events.size() * sizeof(Event)))
        << type;
  }
}

// A bag of two dvs_msgs topics, `a` with the mono bag's first message and `b`
// with its second (50 events each), and with `imu` a third, not-event topic.
void write_two_event_topics(const std::string& path, const std::string& a, const std::string& b, bool imu) {
  const RosMessages mono = decode_db3(kMonoBag);
  Db db(path);
  create_tables(db.db);
  exec(db.db, "INSERT INTO topics VALUES (1, '" + a + "', 'dvs_msgs/msg/EventArray', 'cdr', '')");
  exec(db.db, "INSERT INTO topics VALUES (2, '" + b + "', 'dvs_msgs/msg/EventArray', 'cdr', '')");
  if (imu) exec(db.db, "INSERT INTO topics VALUES (3, '/imu', 'sensor_msgs/msg/Imu', 'cdr', '')");
  db.insert(1, 1, 0, event_array(mono[0], 640, 480));
  db.insert(2, 2, 1, event_array(mono[1], 640, 480));
}

TEST(Rosbag2Reader, TopicChoice) {
  const ScratchDir dir{"test_io_rosbag"};
  const std::string path = dir.file("two.db3");
  write_two_event_topics(path, "/left/events", "/right/events", true);
  const std::string what = evlife::test::open_error(path);  // several event topics: refused
  EXPECT_NE(what.find("--topic"), std::string::npos) << what;
  EXPECT_NE(what.find("/left/events"), std::string::npos) << what;
  EXPECT_NE(what.find("/right/events"), std::string::npos) << what;
  EXPECT_EQ(what.find("/imu"), std::string::npos) << what;
  const ReadAll right = read_all(path, "/right/events");
  ASSERT_FALSE(right.error);
  ASSERT_EQ(right.events.size(), 50u);
  EXPECT_EQ(right.events[0].t_us, 50);  // the second mono message
  for (const std::string bad : {"/imu", "/nope"}) {
    try {
      (void)read_all(path, bad);
      ADD_FAILURE() << bad;
    } catch (const io::ReadError& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
}

/// A split bag's files bag_0.db3 ... in `folder`, each one event of x = y = i at i s.
void write_split_bag(const fs::path& folder, int files) {
  fs::create_directories(folder);
  for (int i = 0; i < files; ++i) {
    Db db((folder / ("bag_" + std::to_string(i) + ".db3")).string());
    create_tables(db.db);
    exec(db.db, "INSERT INTO topics VALUES (1, '/events', 'dvs_msgs/msg/EventArray', 'cdr', '')");
    const auto x = static_cast<std::uint16_t>(i);
    db.insert(1, 1, i, event_array({ros::RosEvent{std::int64_t{i} * 1'000'000, x, x, 1}}, 64, 64));
  }
}

// A split bag without metadata.yaml: its files bag_0 ... bag_11 are read in
// the order they were recorded (as strings bag_10 came before bag_2: the time
// went backwards at the third file and the rest was lost). A folder in MCAP
// storage names the files to give instead.
TEST(Rosbag2Reader, ASplitBagsFilesAreReadInTheirNumbersOrder) {
  const ScratchDir dir{"test_io_rosbag"};
  const fs::path folder = fs::path(dir.file("split"));
  write_split_bag(folder, 12);
  const ReadAll r = read_all(folder.string());
  ASSERT_FALSE(r.error) << r.error->what();
  ASSERT_EQ(r.events.size(), 12u);
  for (int i = 0; i < 12; ++i) {
    EXPECT_EQ(r.events[static_cast<std::size_t>(i)].t_us, i * 1000) << i;
    EXPECT_EQ(r.events[static_cast<std::size_t>(i)].x, i) << i;
  }
  std::ofstream(folder / "metadata.yaml") << "rosbag2_bagfile_information:\n  storage_identifier: mcap\n"
                                             "  relative_file_paths:\n    - bag_0.mcap\n";
  const std::string what = evlife::test::open_error(folder.string());
  EXPECT_NE(what.find("a rosbag2 bag in MCAP storage: give its .mcap file ("), std::string::npos) << what;
  EXPECT_NE(what.find("bag_0.mcap)"), std::string::npos) << what;
  // Up to version 3 rosbag2 listed the files with the folder's name in front (Dashing, Eloquent).
  std::ofstream(folder / "metadata.yaml") << "rosbag2_bagfile_information:\n  version: 3\n  storage_identifier: sqlite3\n"
                                             "  relative_file_paths:\n    - split/bag_0.db3\n    - split/bag_1.db3\n";
  for (const std::string& given : {folder.string(), folder.string() + "/", folder.string() + "/."}) {
    const ReadAll old_bag = read_all(given);
    ASSERT_FALSE(old_bag.error) << given << ": " << old_bag.error->what();
    EXPECT_EQ(old_bag.events.size(), 2u) << given;
  }
  // zstd compression by message (ZstdCompressedMessagesReadAsTheirUncompressedBag) and by file
  // (AFileCompressedBagReadsAsItsFilesUncompressed) reads; another format is refused as such.
  const auto with_compression = [&](const char* format, const char* mode) {
    std::ofstream(folder / "metadata.yaml") << "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: sqlite3\n"
                                               "  relative_file_paths:\n    - bag_0.db3\n  compression_format: " << format
                                            << "\n  compression_mode: " << mode << "\n";
  };
  with_compression("lz4", "FILE");
  const std::string compressed = evlife::test::open_error(folder.string());
  EXPECT_NE(compressed.find("a rosbag2 bag compressed with lz4 (compression_mode FILE): evlife reads uncompressed bags"),
            std::string::npos)
      << compressed;
  with_compression("zstd", "MESSAGE");
  const ReadAll by_message = read_all(folder.string());
  ASSERT_FALSE(by_message.error) << by_message.error->what();
  EXPECT_EQ(by_message.events.size(), 1u);
}

// A metadata.yaml that lists its files in YAML's flow style reads (taken
// for no list before), over one line or several; one without the key, an
// empty file, or a text that is not YAML is named with what is wrong.
TEST(Rosbag2Reader, AMetadataYamlIsReadInFlowStyleAndABrokenOneSaysWhatIsWrong) {
  const ScratchDir dir{"test_io_rosbag"};
  const fs::path folder = fs::path(dir.file("flow"));
  write_split_bag(folder, 2);
  const std::string head = "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: sqlite3\n";
  // One line, or several (a long list as a YAML writer wraps it: "no relative_file_paths key"
  // before), or the list on the line after its key.
  for (const std::string list : {"  relative_file_paths: [bag_0.db3, 'bag_1.db3']\n",
                                 "  relative_file_paths: [bag_0.db3,\n    \"bag_1.db3\"]\n",
                                 "  relative_file_paths:\n    [bag_0.db3, bag_1.db3]\n"}) {
    std::ofstream(folder / "metadata.yaml") << head << list;
    const ReadAll r = read_all(folder.string());
    ASSERT_FALSE(r.error) << list << ": " << r.error->what();
    EXPECT_EQ(r.events.size(), 2u) << list;
  }
  const std::string metadata = (folder / "metadata.yaml").string();
  for (const auto& [text, why] : {std::pair<std::string, std::string>{"", "no relative_file_paths key"},
                                  {"{{{ not yaml: [\n", "not YAML (line 2, column 1: "},
                                  {head, "no relative_file_paths key"},
                                  {head + "  relative_file_paths: []\n", "lists no file under relative_file_paths"}}) {
    std::ofstream(folder / "metadata.yaml") << text;
    const std::string what = evlife::test::open_error(folder.string());
    EXPECT_EQ(what.rfind(metadata + ": ", 0), 0u) << what;
    EXPECT_NE(what.find(why), std::string::npos) << text << ": " << what;
  }
}

/// `file` compressed as rosbag2's compressor does it (--compression-mode
/// file): one zstd stream fed in pieces, ended with the last, to `out`.
void zstd_file(const std::string& file, const std::string& out_path) {
  std::ifstream in(file, std::ios::binary);
  const std::vector<char> bytes{std::istreambuf_iterator<char>(in), {}};
  std::vector<char> out;
  ZSTD_CCtx* ctx = ZSTD_createCCtx();
  std::vector<char> buffer(ZSTD_CStreamOutSize());
  const std::size_t piece = 4096;  // several pieces even for a small file
  for (std::size_t at = 0; at < bytes.size(); at += piece) {
    const bool last = at + piece >= bytes.size();
    ZSTD_inBuffer input{bytes.data() + at, std::min(piece, bytes.size() - at), 0};
    std::size_t left = 0;
    do {
      ZSTD_outBuffer output{buffer.data(), buffer.size(), 0};
      left = ZSTD_compressStream2(ctx, &output, &input, last ? ZSTD_e_end : ZSTD_e_continue);
      EXPECT_EQ(ZSTD_isError(left), 0u);
      out.insert(out.end(), buffer.data(), buffer.data() + output.pos);
    } while (last ? left != 0 : input.pos < input.size);
  }
  ZSTD_freeCCtx(ctx);
  std::ofstream(out_path, std::ios::binary).write(out.data(), static_cast<std::streamsize>(out.size()));
}

// ros2 bag record --compression-mode file --compression-format zstd: each
// closed file becomes NAME.db3.zstd. The bag reads as its files uncompressed,
// through temporary copies that are gone afterwards; so does a recording that
// stopped uncleanly (no metadata.yaml, the last file still a .db3). A later
// file that is corrupt or cut is an error after the earlier files' events.
// A stop (io/stop.h: the command line's Ctrl-C) ends the decompression of a
// file-compressed bag into its copy, which is removed: Ctrl-C waited for the
// whole copy (seconds for gigabytes).
TEST(Rosbag2Reader, AStopEndsTheDecompressionOfAFileCompressedBag) {
  const ScratchDir dir{"test_io_rosbag"};
  const fs::path plain = dir.file("plain.db3"), temp = dir.file("tmp");
  const std::string compressed = dir.file("bag.db3.zstd");
  fs::create_directories(temp);
  ASSERT_EQ(::setenv("TMPDIR", temp.c_str(), 1), 0);
  {
    Db db(plain.string());
    create_tables(db.db);
    exec(db.db, "INSERT INTO topics VALUES (1, '/events', 'dvs_msgs/msg/EventArray', 'cdr', '')");
    db.insert(1, 1, 0, event_array({ros::RosEvent{1000, 1, 2, 1}}, 64, 64));
  }
  zstd_file(plain.string(), compressed);
  std::atomic<bool> stop{true};
  io::set_stop_flag(&stop);
  std::string what;
  try {
    (void)io::open_event_reader(compressed);
  } catch (const io::ReadError& e) {
    what = e.what();
  }
  io::set_stop_flag(nullptr);
  EXPECT_NE(what.find(compressed + ": stopped while decompressing it"), std::string::npos) << what;
  EXPECT_TRUE(fs::is_empty(temp));
  EXPECT_EQ(read_all(compressed).events.size(), 1u);  // without the stop: read
  ::unsetenv("TMPDIR");
}

TEST(Rosbag2Reader, AFileCompressedBagReadsAsItsFilesUncompressed) {
  const ScratchDir dir{"test_io_rosbag"};
  const fs::path plain = dir.file("plain"), zstd = dir.file("zstd"), temp = dir.file("tmp");
  fs::create_directories(plain);
  fs::create_directories(zstd);
  fs::create_directories(temp);
  ASSERT_EQ(::setenv("TMPDIR", temp.c_str(), 1), 0);  // where the copies go
  std::string listed;
  for (int i = 0; i < 3; ++i) {
    const std::string name = "bag_" + std::to_string(i) + ".db3";
    {
      Db db((plain / name).string());
      create_tables(db.db);
      exec(db.db, "INSERT INTO topics VALUES (1, '/events', 'dvs_msgs/msg/EventArray', 'cdr', '')");
      for (int m = 0; m < 2; ++m) {
        std::vector<ros::RosEvent> events;
        for (int k = 0; k < 50; ++k) {
          const int n = (i * 2 + m) * 50 + k;
          events.push_back(ros::RosEvent{std::int64_t{n} * 1000, static_cast<std::uint16_t>(n % 64),
                                         static_cast<std::uint16_t>(n / 64), static_cast<std::int8_t>(n % 2)});
        }
        db.insert(m + 1, 1, i * 2 + m, event_array(events, 64, 64));
      }
    }
    zstd_file((plain / name).string(), (zstd / (name + ".zstd")).string());
    listed += "    - " + name + ".zstd\n";
  }
  std::ofstream(zstd / "metadata.yaml") << "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: sqlite3\n"
                                           "  relative_file_paths:\n" << listed
                                        << "  compression_format: zstd\n  compression_mode: FILE\n";
  const ReadAll reference = read_all(plain.string());
  ASSERT_FALSE(reference.error) << reference.error->what();
  ASSERT_EQ(reference.events.size(), 300u);
  const auto same_as_reference = [&](const ReadAll& r, std::size_t n) {
    return r.events.size() == n && std::memcmp(r.events.data(), reference.events.data(), n * sizeof(Event)) == 0;
  };
  const ReadAll r = read_all(zstd.string());
  ASSERT_FALSE(r.error) << r.error->what();
  EXPECT_EQ(r.format, "rosbag2");
  EXPECT_TRUE(same_as_reference(r, 300));
  ASSERT_EQ(r.streams.size(), 1u);
  EXPECT_EQ(r.streams[0].messages, 6u);
  EXPECT_TRUE(fs::is_empty(temp));  // the decompressed copies are removed
  const auto copies = [&] { return std::distance(fs::directory_iterator(temp), fs::directory_iterator()); };
  {
    // One copy at a time, shared by the readers open on a file at once (a
    // command's probe and its reader): the first file's, until it is read.
    const auto a = io::open_event_reader(zstd.string());
    const auto b = io::open_event_reader(zstd.string());
    EXPECT_EQ(copies(), 1);
  }
  EXPECT_EQ(copies(), 0);
  // One file alone, by its name and content; by its content alone (standard input's copy has no name).
  for (const std::string name : {"bag_0.db3.zstd", "piped"}) {
    if (name == "piped") fs::copy_file(zstd / "bag_0.db3.zstd", temp.parent_path() / name);
    const ReadAll first = read_all((name == "piped" ? temp.parent_path() / name : zstd / name).string());
    ASSERT_FALSE(first.error) << first.error->what();
    EXPECT_EQ(first.format, "rosbag2");
    EXPECT_TRUE(same_as_reference(first, 100)) << name;
  }
  // Stopped uncleanly: no metadata.yaml, the file being written not compressed yet.
  fs::remove(zstd / "metadata.yaml");
  fs::rename(zstd / "bag_2.db3.zstd", temp.parent_path() / "bag_2.db3.zstd");
  fs::copy_file(plain / "bag_2.db3", zstd / "bag_2.db3");
  const ReadAll unclean = read_all(zstd.string());
  ASSERT_FALSE(unclean.error) << unclean.error->what();
  EXPECT_TRUE(same_as_reference(unclean, 300));
  // Stopped while compressing bag_1: its .zstd begun, the .db3 not yet removed: the .db3 is read.
  fs::copy_file(plain / "bag_1.db3", zstd / "bag_1.db3");
  const std::string begun = (zstd / "bag_1.db3.zstd").string();
  fs::resize_file(begun, fs::file_size(begun) / 2);
  const ReadAll compressing = read_all(zstd.string());
  ASSERT_FALSE(compressing.error) << compressing.error->what();
  EXPECT_TRUE(same_as_reference(compressing, 300));
  fs::remove(zstd / "bag_1.db3");
  zstd_file((plain / "bag_1.db3").string(), begun);
  // A later file cut short, or corrupt: the files before it, then the fault naming it.
  fs::remove(zstd / "bag_2.db3");
  const std::string last = (zstd / "bag_2.db3.zstd").string();
  fs::copy_file(temp.parent_path() / "bag_2.db3.zstd", last);
  fs::resize_file(last, fs::file_size(last) / 2);
  const ReadAll cut = read_all(zstd.string());
  ASSERT_TRUE(cut.error);
  EXPECT_EQ(cut.error->path(), last);
  EXPECT_NE(cut.error->reason().find("ends short"), std::string::npos) << cut.error->what();
  EXPECT_TRUE(same_as_reference(cut, 200));
  std::vector<char> bytes;
  {
    std::ifstream in(temp.parent_path() / "bag_2.db3.zstd", std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  // The first block's type made the reserved one (the stream has no checksum: rosbag2's
  // compressor sets none, so flipped literal bytes would pass as data).
  ASSERT_EQ(bytes[4] & 0x20, 0);  // no single segment: a window byte, then the block header at 6
  bytes[6] = static_cast<char>(bytes[6] | 0x06);
  std::ofstream(last, std::ios::binary | std::ios::trunc).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  const ReadAll corrupt = read_all(zstd.string());
  ASSERT_TRUE(corrupt.error);
  EXPECT_EQ(corrupt.error->path(), last);
  EXPECT_NE(corrupt.error->reason().find("corrupt zstd data"), std::string::npos) << corrupt.error->what();
  EXPECT_TRUE(same_as_reference(corrupt, 200)) << corrupt.error->what();
  // The event topic only in the failed file: its fault, not "no event topic".
  const fs::path other = dir.file("other");
  fs::create_directories(other);
  {
    Db db((other / "bag_0.db3").string());
    create_tables(db.db);
    exec(db.db, "INSERT INTO topics VALUES (1, '/notes', 'std_msgs/msg/String', 'cdr', '')");
  }
  fs::copy_file(last, other / "bag_1.db3.zstd");
  const std::string only_later = evlife::test::open_error(other.string());
  EXPECT_NE(only_later.find("bag_1.db3.zstd: corrupt zstd data"), std::string::npos) << only_later;
  // The first file: nothing before it, an open error.
  fs::copy_file(last, zstd / "bag_0.db3.zstd", fs::copy_options::overwrite_existing);
  EXPECT_NE(evlife::test::open_error(zstd.string()).find("bag_0.db3.zstd"), std::string::npos);
  EXPECT_TRUE(fs::is_empty(temp));
  // A TMPDIR that is no folder is named, not replaced by /tmp.
  ASSERT_EQ(::setenv("TMPDIR", (temp / "missing").c_str(), 1), 0);
  const std::string no_tmp = evlife::test::open_error((other / "bag_1.db3.zstd").string());
  EXPECT_NE(no_tmp.find("TMPDIR " + (temp / "missing").string() + " is not a folder"), std::string::npos) << no_tmp;
  ::unsetenv("TMPDIR");
}

// ros2 bag record --compression-mode message --compression-format zstd: every
// message a zstd frame (ZSTD_compress, as rosbag2's compressor). They read as
// the same bag uncompressed; a corrupt frame is an error after the events before.
TEST(Rosbag2Reader, ZstdCompressedMessagesReadAsTheirUncompressedBag) {
  const RosMessages mono = decode_db3(kMonoBag);
  const ScratchDir dir{"test_io_rosbag"};
  const auto write_bag = [&](const std::string& path, bool compressed, std::size_t corrupt_at) {
    Db db(path);
    create_tables(db.db);
    exec(db.db, "INSERT INTO topics VALUES (1, '/events', 'dvs_msgs/msg/EventArray', 'cdr', '')");
    for (std::size_t i = 0; i < mono.size(); ++i) {
      std::vector<std::uint8_t> message = event_array(mono[i], 640, 480);
      if (compressed) {
        std::vector<std::uint8_t> frame(ZSTD_compressBound(message.size()));
        frame.resize(ZSTD_compress(frame.data(), frame.size(), message.data(), message.size(), 3));
        if (i == corrupt_at) frame.resize(frame.size() - 5);  // cut: its blocks end short
        message = frame;
      }
      db.insert(static_cast<int>(i + 1), 1, static_cast<std::int64_t>(i), message);
    }
  };
  const std::string plain = dir.file("plain.db3"), zstd = dir.file("zstd.db3"), cut = dir.file("cut.db3");
  write_bag(plain, false, SIZE_MAX);
  write_bag(zstd, true, SIZE_MAX);
  write_bag(cut, true, 1);  // the second of the bag's two messages
  const ReadAll reference = read_all(plain);
  ASSERT_FALSE(reference.error) << reference.error->what();
  const ReadAll r = read_all(zstd);
  ASSERT_FALSE(r.error) << r.error->what();
  ASSERT_EQ(r.events.size(), reference.events.size());
  EXPECT_EQ(0, std::memcmp(r.events.data(), reference.events.data(), r.events.size() * sizeof(Event)));
  const ReadAll broken = read_all(cut);
  ASSERT_TRUE(broken.error);
  const std::string what = broken.error->what();
  EXPECT_NE(what.find("message 1 of topic '/events': corrupt zstd-compressed message"), std::string::npos) << what;
  EXPECT_EQ(broken.events.size(), mono[0].size());
}

// Two connections of one topic name with two types: refused naming both
// (each was decoded with the first type's layout: a misleading fault).
TEST(Rosbag2Reader, ATopicOfTwoTypesIsRefusedNamingThem) {
  const ScratchDir dir{"test_io_rosbag"};
  const fs::path folder = fs::path(dir.file("mixed"));
  fs::create_directories(folder);
  for (int i = 0; i < 2; ++i) {
    Db db((folder / ("bag_" + std::to_string(i) + ".db3")).string());
    create_tables(db.db);
    exec(db.db, std::string("INSERT INTO topics VALUES (1, '/events', '") +
                    (i == 0 ? "dvs_msgs/msg/EventArray" : "event_camera_msgs/msg/EventPacket") + "', 'cdr', '')");
  }
  const std::string what = evlife::test::open_error(folder.string());
  EXPECT_NE(what.find("topic '/events' holds messages of two types, dvs_msgs/msg/EventArray and "
                      "event_camera_msgs/msg/EventPacket"),
            std::string::npos)
      << what;
}

// A message whose topic_id no topics row lists belongs to no topic: it is
// not read, and `evlife info` lists it as such (it was counted nowhere).
TEST(Rosbag2Reader, MessagesOfNoListedTopicAreCounted) {
  const ScratchDir dir{"test_io_rosbag"};
  const std::string path = dir.file("orphan.db3");
  write_two_event_topics(path, "/left/events", "/right/events", false);
  {
    Db db(path);
    db.insert(3, 99, 2, std::vector<std::uint8_t>{1, 2, 3});
    db.insert(4, 98, 3, std::vector<std::uint8_t>{4});
  }
  io::ReaderOptions options;
  options.topic = "/right/events";
  const auto reader = io::open_unchecked_event_reader(path, options);
  const auto streams = reader->streams();
  ASSERT_EQ(streams.size(), 3u);
  EXPECT_EQ(streams[2].name, "(topic ids no topics row lists)");
  EXPECT_EQ(streams[2].messages, 2u);
  EXPECT_FALSE(streams[2].read);
  const ReadAll right = read_all(path, "/right/events");
  ASSERT_FALSE(right.error);
  EXPECT_EQ(right.events.size(), 50u);  // the topic's own events, as before
  // Every command's summary shows them too (`convert` said nothing: exit 0, unsaid).
  EXPECT_EQ(reader->skipped_record_count(), 2u);
  ASSERT_EQ(reader->skipped_record_kinds().size(), 1u);
  EXPECT_EQ(reader->skipped_record_kinds()[0].kind, "message-of-a-topic-id-no-topics-row-lists");
}

// One byte of the topics table's schema text damaged (`id INTEGER PRIMARY
// KEY` no longer the rowid): every id reads NULL, the JOIN matches no message
// and NOT IN counted none as unlisted: 0 of 100 events, nothing said, exit 0.
TEST(Rosbag2Reader, TopicIdsThatReadNullLeaveTheirMessagesCountedAsUnlisted) {
  const ScratchDir dir{"test_io_rosbag"};
  std::ifstream in(std::string(EVLIFE_SOURCE_DIR) + "/tests/fuzz/corpus/rosbag2/mono_cd.db3", std::ios::binary);
  std::vector<char> bytes{std::istreambuf_iterator<char>(in), {}};
  const std::string schema = "CREATE TABLE topics(id INTEGER PRIMARY KEY";
  const auto at = std::search(bytes.begin(), bytes.end(), schema.begin(), schema.end());
  ASSERT_NE(at, bytes.end());
  at[std::string("CREATE TABLE topics(id INTEGER P").size()] ^= static_cast<char>(0xFF);  // PRIMARY KEY no more
  const std::string path = dir.file("null_ids.db3");
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  const auto reader = io::open_unchecked_event_reader(path, {});
  std::vector<Event> block(1024);
  std::size_t events = 0;
  while (const std::size_t n = reader->read(block)) events += n;
  EXPECT_EQ(events, 0u);
  EXPECT_EQ(reader->skipped_record_count(), 2u) << "the bag's 2 messages, of no listed topic";
}

// metadata.yaml counts the messages rosbag2 was given to write. Fewer in the
// files (a row lost from a .db3, a file left out of relative_file_paths, or
// messages a full recorder cache dropped, which rosbag2 up to Humble counted)
// went unsaid; now counted and shown as skipped records, without an error.
TEST(Rosbag2Reader, MessagesMetadataYamlCountsAndNoFileHoldsAreShown) {
  const ScratchDir dir{"test_io_rosbag"};
  const fs::path folder = fs::path(dir.file("counted"));
  write_split_bag(folder, 2);
  const auto with_count = [&](int events, int other) {
    std::ofstream(folder / "metadata.yaml")
        << "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: sqlite3\n"
           "  relative_file_paths:\n    - bag_0.db3\n    - bag_1.db3\n  topics_with_message_count:\n"
           "    - topic_metadata:\n        name: /imu\n        type: sensor_msgs/msg/Imu\n      message_count: "
        << other << "\n    - topic_metadata:\n        name: /events\n        type: dvs_msgs/msg/EventArray\n"
        << "        serialization_format: cdr\n      message_count: " << events << "\n";
  };
  const auto missing = [&]() -> std::uint64_t {
    const auto reader = io::open_unchecked_event_reader(folder.string(), {});
    std::vector<Event> block(64);
    std::size_t events = 0;
    while (const std::size_t n = reader->read(block)) events += n;
    EXPECT_EQ(events, 2u);  // both files' events, whatever the count
    for (const auto& kind : reader->skipped_record_kinds())
      if (kind.kind == "message-metadata-yaml-counts-and-no-file-holds") return kind.count;
    return 0;
  };
  with_count(2, 7);  // the other topic's count is not this reader's business
  EXPECT_EQ(missing(), 0u);
  with_count(5, 0);
  EXPECT_EQ(missing(), 3u);
  // A file left out of the list: its message is one metadata.yaml counts.
  with_count(2, 0);
  std::string text;
  {
    std::ifstream in(folder / "metadata.yaml");
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  text.replace(text.find("    - bag_1.db3\n"), std::string("    - bag_1.db3\n").size(), "");
  std::ofstream(folder / "metadata.yaml") << text;
  const auto reader = io::open_unchecked_event_reader(folder.string(), {});
  std::vector<Event> block(64);
  EXPECT_EQ(reader->read(block), 1u);
  EXPECT_EQ(reader->read(block), 0u);
  ASSERT_EQ(reader->skipped_record_kinds().size(), 1u);
  EXPECT_EQ(reader->skipped_record_kinds()[0].kind, "message-metadata-yaml-counts-and-no-file-holds");
  EXPECT_EQ(reader->skipped_record_count(), 1u);
}

// ---- the CLI, as a user runs it ----

std::size_t count_lines(const std::string& text) {
  std::size_t n = 0;
  for (const char ch : text) n += ch == '\n' ? 1u : 0u;
  return n;
}

TEST(Rosbag2Cli, ConvertReadsABagFolderAndTakesTopic) {
  const ScratchDir dir{"test_io_rosbag"};
  const auto run = [&](const std::string& args) {
    return evlife::test::run_cli(EVLIFE_CLI_PATH, args, dir.file("cli.log"));
  };
  const std::string out = dir.file("mono.txt");
  const auto ok = run("convert '" + kMonoBag + "' '" + out + "'");
  ASSERT_EQ(ok.exit_code, 0) << ok.output;
  EXPECT_EQ(count_lines(evlife::test::read_text_file(out)), 100u);
  // Two event topics: refused with the list, then chosen with --topic.
  const std::string two = dir.file("two.db3");
  write_two_event_topics(two, "/a/events", "/b/events", false);
  const auto refused = run("convert '" + two + "' '" + dir.file("x.txt") + "'");
  EXPECT_EQ(refused.exit_code, 3) << refused.output;
  EXPECT_NE(refused.output.find("/a/events"), std::string::npos) << refused.output;
  EXPECT_NE(refused.output.find("/b/events"), std::string::npos) << refused.output;
  const auto chosen = run("convert '" + two + "' '" + dir.file("b.txt") + "' --topic /b/events");
  ASSERT_EQ(chosen.exit_code, 0) << chosen.output;
  EXPECT_EQ(count_lines(evlife::test::read_text_file(dir.file("b.txt"))), 50u);
  const auto processed = run("process '" + two + "' --topic /a/events -q -o '" + dir.file("a.csv") + "'");
  ASSERT_EQ(processed.exit_code, 0) << processed.output;
  EXPECT_EQ(count_lines(evlife::test::read_text_file(dir.file("a.csv"))), 50u + 1u) << "header + 50 rows";
}

// ---- faults: events before them kept; the file and message index named ----

std::string copy_bag(const ScratchDir& dir, const std::string& db3, const std::string& name) {
  const std::string path = dir.file(name);
  fs::copy_file(db3, path, fs::copy_options::overwrite_existing);
  fs::permissions(path, fs::perms::owner_read | fs::perms::owner_write);
  return path;
}

TEST(Rosbag2Faults, TruncatedMessageKeepsEventsBefore) {
  const ScratchDir dir{"test_io_rosbag"};
  const std::string path = copy_bag(dir, kLibcaerBag + "/libcaer_rollover_0.db3", "cut.db3");
  std::uint64_t before = 0;
  {
    Db db(path);
    // Events in messages 0-9: payload = data after the 68 header bytes (frame_id
    // "camera", encoding "libcaer"), 8 bytes per event.
    sqlite3_stmt* s = nullptr;
    ASSERT_EQ(sqlite3_prepare_v2(db.db, "SELECT SUM((length(data) - 68) / 8) FROM "
                                        "(SELECT data FROM messages ORDER BY timestamp, id LIMIT 10)",
                                 -1, &s, nullptr),
              SQLITE_OK);
    ASSERT_EQ(sqlite3_step(s), SQLITE_ROW);
    before = static_cast<std::uint64_t>(sqlite3_column_int64(s, 0));
    sqlite3_finalize(s);
    exec(db.db, "UPDATE messages SET data = substr(data, 1, length(data) - 3) WHERE id = "
                "(SELECT id FROM messages ORDER BY timestamp, id LIMIT 1 OFFSET 10)");
  }
  const ReadAll full = read_all(kLibcaerBag);
  const ReadAll cut = read_all(path);
  ASSERT_TRUE(cut.error);
  const std::string what = cut.error->what();
  EXPECT_NE(what.find(path), std::string::npos) << what;
  EXPECT_NE(what.find("message 10 "), std::string::npos) << what;
  ASSERT_EQ(cut.events.size(), before);
  EXPECT_EQ(0, std::memcmp(cut.events.data(), full.events.data(), before * sizeof(Event)));
}

// A database cut inside its last page: SQLite would read the missing bytes
// as zeros without an error (its integrity check passes), and the zeroed
// libcaer words came out as events up to 72 min later, exit 0. The size its
// header states is checked when the file opens.
TEST(Rosbag2Faults, ADatabaseShorterThanItsHeaderStatesIsCut) {
  const ScratchDir dir{"test_io_rosbag"};
  const std::string path = copy_bag(dir, kLibcaerBag + "/libcaer_rollover_0.db3", "short.db3");
  const std::uintmax_t whole = fs::file_size(path);
  fs::resize_file(path, whole - 10);
  try {
    (void)read_all(path);
    FAIL() << "a cut database was read";
  } catch (const io::ReadError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find("cut: the database has " + std::to_string(whole - 10) + " bytes where its header states"),
              std::string::npos)
        << what;
    EXPECT_EQ(e.byte_offset(), static_cast<std::int64_t>(whole - 10));
  }
}

// Little-endian fields with CDR's alignment (relative to `base`, after the
// encapsulation header; ROS 1: none): a message built by hand.
struct MessageBytes {
  std::vector<std::uint8_t> bytes;
  std::size_t base = 0;
  bool aligned = true;
  template <typename T>
  MessageBytes& put(T value) {
    while (aligned && (bytes.size() - base) % sizeof(T) != 0) bytes.push_back(0);
    const auto* p = reinterpret_cast<const std::uint8_t*>(&value);
    bytes.insert(bytes.end(), p, p + sizeof(T));
    return *this;
  }
  MessageBytes& text(const std::string& s) {
    put(static_cast<std::uint32_t>(s.size() + 1));
    bytes.insert(bytes.end(), s.begin(), s.end());
    bytes.push_back(0);
    return *this;
  }
};

// A length or count smaller than the events behind it would lose the rest of
// the message unseen: the bytes after the last field are a fault (beyond
// CDR's padding to 4 bytes), after the events the count covered.
TEST(RosPayloads, BytesAfterTheEventsAreAFaultNotDropped) {
  for (const std::size_t extra : {std::size_t{0}, std::size_t{3}, std::size_t{8}}) {
    MessageBytes packet{{0x00, 0x01, 0x00, 0x00}, 4};  // CDR little-endian
    packet.put(std::int32_t{1}).put(std::uint32_t{0}).text("camera");
    packet.put(std::uint32_t{480}).put(std::uint32_t{640}).put(std::uint64_t{0}).put(std::uint64_t{0});
    packet.text("mono").put(std::uint8_t{0}).put(std::uint32_t{0});  // an events field of 0 bytes
    packet.bytes.resize(packet.bytes.size() + extra, 0);
    ros::MessageDecoder decoder(ros::MessageKind::event_packet);
    std::vector<ros::RosEvent> events;
    const auto fault = decoder.decode(packet.bytes, events);
    EXPECT_EQ(fault.has_value(), extra > 3) << extra << " bytes after";
    if (fault) {
      EXPECT_NE(fault->what.find(std::to_string(extra) + " bytes follow the field 'events'"), std::string::npos)
          << fault->what;
    }
  }
  // A width no camera has (it would read as -1 in an int) is a fault, not a sensor.
  MessageBytes wide{{0x00, 0x01, 0x00, 0x00}, 4};
  wide.put(std::int32_t{1}).put(std::uint32_t{0}).text("camera");
  wide.put(std::uint32_t{480}).put(std::uint32_t{0xFFFFFFFF}).put(std::uint64_t{0}).put(std::uint64_t{0});
  wide.text("mono").put(std::uint8_t{0}).put(std::uint32_t{0});
  std::vector<ros::RosEvent> none;
  const auto wide_fault = ros::MessageDecoder(ros::MessageKind::event_packet).decode(wide.bytes, none);
  ASSERT_TRUE(wide_fault);
  EXPECT_NE(wide_fault->what.find("480/4294967295 beyond any camera's"), std::string::npos) << wide_fault->what;
  // ROS 1 dvs_msgs/EventArray saying 1 event and holding 2: the first is read.
  MessageBytes array{{}, 0, false};
  array.put(std::uint32_t{7}).put(std::int32_t{1}).put(std::uint32_t{0}).text("camera");
  array.put(std::uint32_t{180}).put(std::uint32_t{240}).put(std::uint32_t{1});
  for (int i = 0; i < 2; ++i) {
    array.put(std::uint16_t{10}).put(std::uint16_t{20}).put(std::int32_t{1}).put(std::uint32_t{500}).put(std::uint8_t{1});
  }
  ros::MessageDecoder decoder(ros::MessageKind::event_array, ros::Serialization::ros1);
  std::vector<ros::RosEvent> events;
  const auto fault = decoder.decode(array.bytes, events);
  ASSERT_TRUE(fault);
  EXPECT_NE(fault->what.find("13 bytes follow the field 'events'"), std::string::npos) << fault->what;
  EXPECT_EQ(events.size(), 1u);
  array.bytes.resize(array.bytes.size() - 13);
  EXPECT_FALSE(decoder.decode(array.bytes, events));
  EXPECT_EQ(events.size(), 1u);
}

// libcaer_cmp as the ROS 2 libcaer driver encodes a message (its default encoding): per
// message, time in µs after the first event (TIME_HIGH/TIME_LOW words when it changes), ADDR_X
// when x changes, and per group of 8 rows of one x, time and polarity an ADDR_Y (one event) or
// VECT_BASE_Y + VECT_8 (several). Written here from that description, apart from the decoder.
std::vector<std::uint8_t> libcaer_cmp_message(const std::vector<ros::RosEvent>& events) {
  std::vector<std::uint8_t> out;
  const auto word = [&out](std::uint32_t code, std::uint32_t rest) {
    const auto w = static_cast<std::uint16_t>((code << 12) | rest);
    out.push_back(static_cast<std::uint8_t>(w & 0xFF));
    out.push_back(static_cast<std::uint8_t>(w >> 8));
  };
  std::uint32_t high = 0, low = 0, x = events.front().x, y_group = 0xFFFF, mask = 0;
  int polarity = 0;  // none yet
  const auto flush = [&] {
    if (mask == 0) return;
    const std::uint32_t on = polarity > 0 ? 0x800u : 0u;
    if (std::popcount(mask) == 1) {
      // The row of the one bit set. (The driver writes the group's first row, y_first, which is
      // another row where a flush by time, x or polarity left the group open: its encoder's
      // slip, decoded as written by event_camera_codecs and by evlife.)
      word(3, y_group | static_cast<std::uint32_t>(std::countr_zero(mask)) | on);
    } else {
      word(4, y_group | on);
      word(5, mask);
    }
    mask = 0;
  };
  word(2, x);
  for (const ros::RosEvent& e : events) {
    const auto dt = static_cast<std::uint32_t>((e.t_ns - events.front().t_ns) / 1000);
    if ((dt & 0xFFF000u) != high) flush(), high = dt & 0xFFF000u, word(0, high >> 12);
    if ((dt & 0xFFFu) != low) flush(), low = dt & 0xFFFu, word(1, low);
    if (e.x != x) flush(), x = e.x, word(2, x);
    if (e.p != polarity) flush(), polarity = e.p;
    if ((e.y & ~7u) != y_group) flush(), y_group = e.y & ~7u;
    mask |= 1u << (e.y & 7u);
  }
  flush();
  return out;
}

std::vector<ros::RosEvent> sorted(std::vector<ros::RosEvent> v) {
  std::sort(v.begin(), v.end(), [](const ros::RosEvent& a, const ros::RosEvent& b) {
    return std::tie(a.t_ns, a.x, a.y, a.p) < std::tie(b.t_ns, b.x, b.y, b.p);
  });
  return v;
}

// The shared libcaer bag's 201 messages re-encoded as libcaer_cmp decode to their events (in
// time, x and y order within one microsecond: a vector word lists its rows in order).
TEST(RosPayloads, LibcaerCmpDecodesTheDriversEncoding) {
  const RosMessages messages = decode_db3(kLibcaerBag);
  ros::LibcaerCmpState state;
  std::size_t vectors = 0, total = 0;
  for (const std::vector<ros::RosEvent>& m : messages) {
    if (m.empty()) continue;
    const std::vector<std::uint8_t> payload = libcaer_cmp_message(m);
    for (std::size_t at = 1; at < payload.size(); at += 2) vectors += (payload[at] >> 4) == 5 ? 1u : 0u;
    std::vector<ros::RosEvent> out;
    const auto fault = ros::decode_libcaer_cmp(payload, static_cast<std::uint64_t>(m.front().t_ns), 640, 480, state, out);
    ASSERT_FALSE(fault) << fault->what;
    const std::vector<ros::RosEvent> want = sorted(m), got = sorted(out);
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t i = 0; i < want.size(); ++i) {
      ASSERT_EQ(got[i].t_ns, want[i].t_ns) << i;
      ASSERT_EQ(got[i].x, want[i].x) << i;
      ASSERT_EQ(got[i].y, want[i].y) << i;
      ASSERT_EQ(got[i].p, want[i].p) << i;
    }
    total += m.size();
  }
  EXPECT_GT(total, 100'000u);
  EXPECT_GT(vectors, 50u) << "the vector words are exercised";
  // Faults name their byte: a row before any column, an unknown word, a row outside the sensor.
  std::vector<ros::RosEvent> out;
  ros::LibcaerCmpState fresh;
  const std::vector<std::uint8_t> no_x = {0x07, 0x38};  // ADDR_Y 7, ON
  auto fault = ros::decode_libcaer_cmp(no_x, 0, 346, 260, fresh, out);
  ASSERT_TRUE(fault);
  EXPECT_NE(fault->what.find("ADDR_Y word before any ADDR_X"), std::string::npos) << fault->what;
  const std::vector<std::uint8_t> unknown = {0x05, 0x20, 0x00, 0x70};  // ADDR_X 5, code 7
  fault = ros::decode_libcaer_cmp(unknown, 0, 346, 260, fresh, out);
  ASSERT_TRUE(fault);
  EXPECT_EQ(fault->byte_in_message, 2u);
  const std::vector<std::uint8_t> outside = {0x05, 0x20, 0x07, 0x31, 0x09, 0x31};  // y 263, then 265
  out.clear();
  fault = ros::decode_libcaer_cmp(outside, 0, 346, 264, fresh, out);
  ASSERT_TRUE(fault);
  EXPECT_EQ(fault->byte_in_message, 4u);
  EXPECT_EQ(out.size(), 1u);  // the event before it
  // An ADDR_Y's polarity is its event's: a vector after it keeps its VECT_BASE_Y's.
  const std::vector<std::uint8_t> mixed = {0x05, 0x20, 0x00, 0x48, 0x14, 0x30, 0x01, 0x50};  // x 5, base 0 ON, y 20 OFF, bit 0
  out.clear();
  ros::LibcaerCmpState polarity_state;
  ASSERT_FALSE(ros::decode_libcaer_cmp(mixed, 0, 346, 260, polarity_state, out));
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].y, 20);
  EXPECT_EQ(out[0].p, -1);
  EXPECT_EQ(out[1].y, 0);
  EXPECT_EQ(out[1].p, 1);
  // Through the EventPacket message: encoding "libcaer_cmp" (refused as unsupported before).
  MessageBytes packet{{0x00, 0x01, 0x00, 0x00}, 4};
  packet.put(std::int32_t{1}).put(std::uint32_t{0}).text("camera");
  packet.put(std::uint32_t{260}).put(std::uint32_t{346}).put(std::uint64_t{0}).put(std::uint64_t{5'000'000});
  packet.text("libcaer_cmp").put(std::uint8_t{0}).put(std::uint32_t{6});
  for (const std::uint8_t b : {0x03, 0x10, 0x05, 0x20, 0x07, 0x38}) packet.bytes.push_back(b);  // 3 µs, x 5, y 7 ON
  ros::MessageDecoder decoder(ros::MessageKind::event_packet);
  std::vector<ros::RosEvent> events;
  ASSERT_FALSE(decoder.decode(packet.bytes, events));
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].t_ns, 5'003'000);
  EXPECT_EQ(events[0].x, 5);
  EXPECT_EQ(events[0].y, 7);
  EXPECT_EQ(events[0].p, 1);
}

TEST(Rosbag2Faults, UnknownEncodingAndNotABag) {
  const ScratchDir dir{"test_io_rosbag"};
  const std::string path = copy_bag(dir, kMonoBag + "/test_data_mono_cd_0.db3", "enc.db3");
  {
    Db db(path);
    exec(db.db, "UPDATE messages SET data = replace(data, CAST('mono' AS BLOB), CAST('mpeg' AS BLOB)) "
                "WHERE id = (SELECT MAX(id) FROM messages)");
  }
  const ReadAll r = read_all(path);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.events.size(), 50u);
  EXPECT_NE(std::string(r.error->what()).find("unsupported event encoding 'mpeg'"), std::string::npos)
      << r.error->what();
  // An SQLite file that is not a bag.
  const std::string other = dir.file("other.db3");
  {
    Db db(other);
    exec(db.db, "CREATE TABLE t(a INTEGER)");
  }
  EXPECT_THROW((void)io::open_event_reader(other), io::ReadError);
  // A directory that is no bag.
  fs::create_directories(dir.file("empty"));
  EXPECT_THROW((void)io::open_event_reader(dir.file("empty")), io::ReadError);
}

}  // namespace
