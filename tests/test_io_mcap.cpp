// ROS 2 MCAP files (io/formats/src/mcap_*): the shared rosbag2 bags' CDR messages,
// repackaged by the independent test-only writer tests/data/mcap/make_mcap.py
// (chunks uncompressed / zstd / lz4, single or several frames, with and
// without summary, unchunked, messages reversed inside chunks), decode to the same events as the .db3
// bags and reproduce their checksums (../shared/data/PROVENANCE.md); topics
// and counts for `evlife info`; faults (chunk, data-section and summary CRCs
// among them) keep the events before them.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "evlife/io/event_reader.h"
#include "mcap_messages.h"
#include "read_all.h"
#include "ros2_bag_reference.h"
#include "ros_messages.h"
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

const std::string kMcap = std::string(EVLIFE_MCAP_TEST_DIR) + "/";
const std::string kBags = std::string(EVLIFE_SHARED_DATA_DIR) + "/rosbag/";
const std::map<std::string, std::string> kDb3 = {{"evt3", kBags + "test_data_evt3_trigger"},
                                                 {"libcaer", kBags + "test_data_libcaer_rollover"},
                                                 {"mono", kBags + "test_data_mono_cd"}};
const char* const kCompressions[] = {"none", "zstd", "lz4"};

/// The event topic's messages decoded, through the MCAP container (white box).
RosMessages decode_mcap(const std::string& path, std::vector<std::uint64_t>* record_at = nullptr) {
  io::mcap::McapMessages bag(path);
  const ros::TopicInfo* topic = nullptr;
  for (const ros::TopicInfo& t : bag.topics())
    if (ros::message_kind(t.type) != ros::MessageKind::not_events) topic = &t;
  EXPECT_NE(topic, nullptr);
  ros::MessageDecoder decoder(ros::message_kind(topic->type));
  bag.select(topic->name);
  RosMessages r;
  io::mcap::McapMessages::Message m;
  std::vector<ros::RosEvent> events;
  while (bag.next(m)) {
    EXPECT_EQ(m.index, r.size());
    const auto fault = decoder.decode(m.data, events);
    EXPECT_FALSE(fault) << path << " message " << m.index << ": " << fault->what;
    r.push_back(events);
    if (record_at != nullptr) record_at->push_back(m.record_at);
  }
  return r;
}

bool same(const std::vector<ros::RosEvent>& a, const std::vector<ros::RosEvent>& b) {
  return a.size() == b.size() &&
         std::equal(a.begin(), a.end(), b.begin(), [](const ros::RosEvent& u, const ros::RosEvent& v) {
           return u.t_ns == v.t_ns && u.x == v.x && u.y == v.y && u.p == v.p;
         });
}

using evlife::test::ReadAll;

ReadAll read_all(const std::string& path, const std::string& topic = {}) {
  io::ReaderOptions options;
  options.topic = topic;
  return evlife::test::read_all(path, options, 777);
}

bool same_events(const std::vector<Event>& a, const std::vector<Event>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Event)) == 0;
}

TEST(McapContainer, EveryCompressionDecodesToTheDb3MessagesAndItsChecksums) {
  for (const auto& [bag, db3] : kDb3) {
    const RosMessages expected = decode_db3(db3);
    ASSERT_EQ(ros_sums(expected), kRosBagSums.at(bag)) << bag;
    for (const char* how : kCompressions) {
      const std::string path = kMcap + bag + "_" + how + ".mcap";
      const RosMessages got = decode_mcap(path);
      EXPECT_EQ(ros_sums(got), kRosBagSums.at(bag)) << path;
      ASSERT_EQ(got.size(), expected.size()) << path;
      for (std::size_t i = 0; i < got.size(); ++i) EXPECT_TRUE(same(got[i], expected[i])) << path << " message " << i;
    }
  }
}

TEST(McapContainer, MessagesReversedInsideChunksComeOutInLogTimeOrder) {
  const RosMessages expected = decode_db3(kDb3.at("evt3"));
  const RosMessages got = decode_mcap(kMcap + "evt3_reversed.mcap");
  ASSERT_EQ(got.size(), expected.size());
  for (std::size_t i = 0; i < got.size(); ++i) EXPECT_TRUE(same(got[i], expected[i])) << "message " << i;
}

// A zstd or lz4 stream may hold several frames (one without its content
// size, a skippable frame between): the same messages as one frame.
TEST(McapContainer, ChunksOfSeveralFramesDecodeAsOneFrame) {
  for (const char* bag : {"evt3", "mono"}) {
    const RosMessages expected = decode_db3(kDb3.at(bag));
    const ReadAll single = read_all(kMcap + bag + "_none.mcap");
    ASSERT_FALSE(single.error) << single.error->what();
    for (const char* how : {"zstd", "lz4"}) {
      const std::string path = kMcap + bag + "_" + how + "_frames.mcap";
      const RosMessages got = decode_mcap(path);
      EXPECT_EQ(ros_sums(got), kRosBagSums.at(bag)) << path;
      ASSERT_EQ(got.size(), expected.size()) << path;
      for (std::size_t i = 0; i < got.size(); ++i) EXPECT_TRUE(same(got[i], expected[i])) << path << " message " << i;
      const ReadAll r = read_all(path);
      ASSERT_FALSE(r.error) << r.error->what();
      EXPECT_TRUE(same_events(r.events, single.events)) << path;
    }
  }
}

// `mcap convert` keeps a ROS 1 bag's messages in their ROS 1 serialization (message encoding
// ros1): read as the bag is (refused before as "not cdr").
TEST(McapReader, Ros1EncodedMessagesReadAsTheRos1Bag) {
  const ReadAll bag = read_all(std::string(EVLIFE_SOURCE_DIR) + "/tests/data/ros1/mono_dvs.bag");
  const ReadAll r = read_all(kMcap + "mono_ros1.mcap");
  ASSERT_FALSE(r.error) << r.error->what();
  EXPECT_EQ(r.sensor, bag.sensor);
  ASSERT_GE(r.events.size(), bag.events.size());  // the bag holds the first two messages
  ASSERT_FALSE(bag.events.empty());
  EXPECT_TRUE(same_events(std::vector<Event>(r.events.begin(), r.events.begin() + static_cast<std::ptrdiff_t>(bag.events.size())),
                          bag.events));
  const ReadAll cdr = read_all(kMcap + "mono_zstd.mcap");  // the same events, all of them
  EXPECT_TRUE(same_events(r.events, cdr.events)) << r.events.size() << " against " << cdr.events.size();
}

// Chunks are read in file order and not merged: events going backwards stop
// the read with the time-order error, after the events before them.
TEST(McapReader, ChunksOutOfTimeOrderStopWithTheTimeOrderError) {
  const RosMessages db3 = decode_db3(kDb3.at("libcaer"));
  std::vector<Event> first;  // messages 20-39, written first
  for (std::size_t i = 20; i < 40; ++i)
    for (const ros::RosEvent& e : db3[i]) first.push_back(Event{e.t_ns / 1000, e.x, e.y, e.p});
  const ReadAll r = read_all(kMcap + "libcaer_swapped.mcap");
  ASSERT_TRUE(r.error);
  const std::string what = r.error->what();
  EXPECT_NE(what.find("libcaer_swapped.mcap"), std::string::npos) << what;
  EXPECT_EQ(r.error->event_index(), static_cast<std::int64_t>(first.size())) << what;
  // Where the message that went back lies (it named no place before).
  EXPECT_GT(r.error->byte_offset(), 0) << what;
  EXPECT_LT(r.error->byte_offset(), static_cast<std::int64_t>(fs::file_size(kMcap + "libcaer_swapped.mcap"))) << what;
  EXPECT_TRUE(same_events(r.events, first)) << r.events.size() << " events, expected " << first.size();
}

TEST(McapReader, EventArraysEqualTheDb3ReadersAndTopicsAreListed) {
  for (const auto& [bag, db3] : kDb3) {
    const ReadAll expected = read_all(db3);
    ASSERT_FALSE(expected.error) << expected.error->what();
    for (const char* how : kCompressions) {
      const std::string path = kMcap + bag + "_" + how + ".mcap";
      const ReadAll got = read_all(path);
      ASSERT_FALSE(got.error) << got.error->what();
      EXPECT_EQ(got.format, "mcap");
      EXPECT_EQ(got.sensor, expected.sensor) << path;
      EXPECT_EQ(got.triggers, expected.triggers) << path;
      EXPECT_TRUE(same_events(got.events, expected.events)) << path;
      // Streams: the db3's topic with its type and count (+ /chatter in the mono files).
      ASSERT_EQ(got.streams.size(), expected.streams.size() + (bag == "mono" ? 1u : 0u)) << path;
      const io::ContainerStream& db3_topic = expected.streams.at(0);
      bool found = false;
      for (const io::ContainerStream& s : got.streams) {
        if (s.name != db3_topic.name) continue;
        found = true;
        EXPECT_EQ(s.type, db3_topic.type);
        EXPECT_EQ(s.messages, db3_topic.messages);
        EXPECT_TRUE(s.read);
      }
      EXPECT_TRUE(found) << path;
    }
  }
  EXPECT_EQ(read_all(kMcap + "evt3_none.mcap").triggers, 2u);
}

TEST(McapReader, UnchunkedFileWithoutSummaryReadsAlike) {
  const ReadAll chunked = read_all(kMcap + "mono_zstd.mcap");
  const ReadAll plain = read_all(kMcap + "mono_unchunked.mcap");
  ASSERT_FALSE(plain.error) << plain.error->what();
  EXPECT_TRUE(same_events(plain.events, chunked.events));
  ASSERT_EQ(plain.streams.size(), 2u);  // from the scan: both topics with their counts
  for (const io::ContainerStream& s : plain.streams) EXPECT_EQ(s.messages, 2u) << s.name;
}

TEST(McapReader, TopicThatIsNotEventsIsRefused) {
  try {
    (void)read_all(kMcap + "mono_lz4.mcap", "/chatter");
    FAIL() << "a std_msgs/String topic was read as events";
  } catch (const io::ReadError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("mono_lz4.mcap"), std::string::npos) << what;
    EXPECT_NE(what.find("std_msgs/msg/String, not an event message"), std::string::npos) << what;
  }
  EXPECT_EQ(read_all(kMcap + "mono_lz4.mcap", "/event_camera/events").events.size(), 100u);
}

// ---- CLI: info and convert (the registry sniffs .mcap) ----

using evlife::test::ScratchDir;

TEST(McapCli, InfoListsTopicsAndConvertMatchesTheDb3) {
  const ScratchDir dir{"test_io_mcap"};
  const auto run = [&](const std::string& args) {
    return evlife::test::run_cli(EVLIFE_CLI_PATH, args, dir.file("cli.log"));
  };
  const auto info = run("info '" + kMcap + "mono_zstd.mcap'");
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_NE(info.output.find("mcap"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("/chatter"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("std_msgs/msg/String"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("event_array_msgs/msg/EventArray"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("640x480"), std::string::npos) << info.output;
  const auto a = run("convert '" + kMcap + "libcaer_lz4.mcap' '" + dir.file("a.txt") + "'");
  ASSERT_EQ(a.exit_code, 0) << a.output;
  const auto b = run("convert '" + kDb3.at("libcaer") + "' '" + dir.file("b.txt") + "'");
  ASSERT_EQ(b.exit_code, 0) << b.output;
  const std::string text = evlife::test::read_text_file(dir.file("a.txt"));
  EXPECT_GT(text.size(), 334331u);
  EXPECT_EQ(text, evlife::test::read_text_file(dir.file("b.txt")));
}

// ---- faults: file, byte offset and message index named; events before kept ----

std::vector<char> bytes_of(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<char>(std::istreambuf_iterator<char>(in), {});
}

void write_bytes(const std::string& path, const std::vector<char>& b) {
  std::ofstream(path, std::ios::binary).write(b.data(), static_cast<std::streamsize>(b.size()));
}

/// File offsets of the top-level Chunk records (opcode 0x06), walked here
/// from the spec's record framing: magic, then u8 opcode + u64 length + content.
std::vector<std::uint64_t> chunk_offsets(const std::vector<char>& b) {
  std::vector<std::uint64_t> chunks;
  for (std::uint64_t at = 8; at + 9 <= b.size();) {
    std::uint64_t len = 0;
    std::memcpy(&len, b.data() + at + 1, 8);
    if (b[at] == 0x06) chunks.push_back(at);
    if (b[at] == 0x0F) break;  // DataEnd
    at += 9 + len;
  }
  return chunks;
}

/// Events (µs) of the messages stored in chunks before file offset `limit`.
std::size_t events_before(const std::string& path, std::uint64_t limit) {
  std::vector<std::uint64_t> at;
  const RosMessages all = decode_mcap(path, &at);
  std::size_t n = 0;
  for (std::size_t i = 0; i < all.size(); ++i)
    if (at[i] < limit) n += all[i].size();
  return n;
}

struct Faulty {
  ReadAll r;
  std::size_t expected_events = 0;
  std::uint64_t chunk_at = 0;
};

/// Copies `source`, lets `damage` change the bytes given the chunk offsets
/// (it returns the offset of the damaged chunk), and reads the copy.
template <typename Damage>
Faulty read_damaged(const ScratchDir& dir, const std::string& source, const std::string& name, Damage damage) {
  std::vector<char> b = bytes_of(kMcap + source);
  const std::vector<std::uint64_t> chunks = chunk_offsets(b);
  EXPECT_GE(chunks.size(), 4u);
  Faulty f;
  f.chunk_at = damage(b, chunks);
  f.expected_events = events_before(kMcap + source, f.chunk_at);
  const std::string path = dir.file(name);
  write_bytes(path, b);
  f.r = read_all(path);
  return f;
}

void expect_fault(const Faulty& f, const std::vector<Event>& full, const std::string& name, const std::string& what) {
  ASSERT_TRUE(f.r.error) << name;
  const std::string message = f.r.error->what();
  EXPECT_NE(message.find(name), std::string::npos) << message;
  EXPECT_NE(message.find(what), std::string::npos) << message;
  EXPECT_NE(message.find("messages of the topic"), std::string::npos) << message;
  EXPECT_EQ(f.r.error->byte_offset(), static_cast<std::int64_t>(f.chunk_at)) << message;
  EXPECT_GT(f.expected_events, 0u);
  ASSERT_EQ(f.r.events.size(), f.expected_events) << message;
  EXPECT_EQ(0, std::memcmp(f.r.events.data(), full.data(), f.expected_events * sizeof(Event)));
}

TEST(McapFaults, TruncatedFileKeepsTheEventsOfTheWholeChunksBefore) {
  const ScratchDir dir{"test_io_mcap"};
  const std::vector<Event> full = read_all(kMcap + "libcaer_zstd.mcap").events;
  const Faulty f = read_damaged(dir, "libcaer_zstd.mcap", "cut.mcap", [](std::vector<char>& b, const auto& chunks) {
    b.resize(chunks[3] + 100);  // inside the fourth chunk
    return chunks[3];
  });
  expect_fault(f, full, "cut.mcap", "runs past the end of the file (truncated)");
}

TEST(McapFaults, CorruptChunkFailsItsCrcOrDecompression) {
  const ScratchDir dir{"test_io_mcap"};
  for (const char* how : kCompressions) {
    const std::string source = std::string("evt3_") + how + ".mcap";
    const std::vector<Event> full = read_all(kMcap + source).events;
    const std::string name = std::string("corrupt_") + how + ".mcap";
    const Faulty f = read_damaged(dir, source, name, [](std::vector<char>& b, const auto& chunks) {
      const std::uint64_t middle = (chunks[2] + chunks[3]) / 2;
      for (std::uint64_t i = middle; i < middle + 16; ++i) b[i] = static_cast<char>(b[i] ^ 0x5A);
      return chunks[2];
    });
    expect_fault(f, full, name, std::string(how) == "none" ? "chunk CRC mismatch" : "MCAP");
  }
}

TEST(McapFaults, CorruptRecordInsideAChunkKeepsTheMessagesBeforeItInThatChunk) {
  const ScratchDir dir{"test_io_mcap"};
  const std::string source = "evt3_none.mcap";
  const std::vector<Event> full = read_all(kMcap + source).events;
  std::vector<char> b = bytes_of(kMcap + source);
  const std::uint64_t chunk = chunk_offsets(b).at(2);
  // Chunk content: 3 u64, u32 CRC (set to 0 = not given, so that the damage
  // below is found by the record framing), compression "" (u32 0), u64 length.
  std::memset(b.data() + chunk + 9 + 24, 0, 4);
  const std::uint64_t first = chunk + 9 + 40;  // the chunk's first record: a Message
  ASSERT_EQ(b[first], 0x05);
  std::uint64_t len = 0;
  std::memcpy(&len, b.data() + first + 1, 8);
  const std::uint64_t second = first + 9 + len;
  const std::uint64_t huge = ~std::uint64_t{0};
  std::memcpy(b.data() + second + 1, &huge, 8);
  const std::string path = dir.file("record.mcap");
  write_bytes(path, b);
  std::vector<std::uint64_t> at;
  const RosMessages messages = decode_mcap(kMcap + source, &at);
  std::size_t expected = 0;
  bool first_of_chunk = true;
  for (std::size_t i = 0; i < messages.size(); ++i) {
    if (at[i] < chunk || (at[i] == chunk && first_of_chunk)) expected += messages[i].size();
    if (at[i] == chunk) first_of_chunk = false;
  }
  const ReadAll r = read_all(path);
  ASSERT_TRUE(r.error);
  const std::string what = r.error->what();
  EXPECT_NE(what.find("corrupt record at byte " + std::to_string(second - first) + " of the MCAP chunk"),
            std::string::npos) << what;
  EXPECT_EQ(r.error->byte_offset(), static_cast<std::int64_t>(chunk)) << what;
  ASSERT_EQ(r.events.size(), expected) << what;
  EXPECT_EQ(0, std::memcmp(r.events.data(), full.data(), expected * sizeof(Event)));
}

// A Message on a channel no Channel record defines, or a Channel record that
// gives a known id another topic: its messages were dropped (or went to the
// other topic), exit 0, uncounted. The spec forbids both: now an input error
// at the chunk, after the messages before it.
TEST(McapFaults, AMessageOfAnUndefinedChannelOrARedefinedChannelIsAnError) {
  const ScratchDir dir{"test_io_mcap"};
  const std::string source = "evt3_none.mcap";
  const std::vector<Event> full = read_all(kMcap + source).events;
  const std::vector<char> good = bytes_of(kMcap + source);
  {
    std::vector<char> b = good;
    const std::uint64_t chunk = chunk_offsets(b).at(2);
    std::memset(b.data() + chunk + 9 + 24, 0, 4);  // its CRC: not given (as above)
    const std::uint64_t first = chunk + 9 + 40;      // its first record: a Message
    ASSERT_EQ(b[first], 0x05);
    b[first + 9] = 9;  // channel_id 9
    b[first + 10] = 0;
    const std::string path = dir.file("undefined_channel.mcap");
    write_bytes(path, b);
    const ReadAll r = read_all(path);
    ASSERT_TRUE(r.error);
    EXPECT_NE(std::string(r.error->what()).find("is on channel 9, which no Channel record defines before it"),
              std::string::npos) << r.error->what();
    EXPECT_EQ(r.error->byte_offset(), static_cast<std::int64_t>(chunk));
    ASSERT_GT(r.events.size(), 0u);
    ASSERT_LT(r.events.size(), full.size());
    EXPECT_EQ(0, std::memcmp(r.events.data(), full.data(), r.events.size() * sizeof(Event)));
  }
  {
    // The first chunk's Channel record renamed (same length): the summary's channel 1 is the topic.
    std::vector<char> b = good;
    const std::uint64_t chunk = chunk_offsets(b).at(0);
    std::memset(b.data() + chunk + 9 + 24, 0, 4);
    const std::string topic = "/event_camera/events";
    const auto it = std::search(b.begin() + static_cast<std::ptrdiff_t>(chunk), b.end(), topic.begin(), topic.end());
    ASSERT_NE(it, b.end());
    *(it + static_cast<std::ptrdiff_t>(topic.size()) - 1) = 'z';
    const std::string path = dir.file("redefined_channel.mcap");
    write_bytes(path, b);
    const ReadAll r = read_all(path);
    ASSERT_TRUE(r.error);
    EXPECT_NE(std::string(r.error->what()).find("redefined as topic '/event_camera/eventz'"), std::string::npos)
        << r.error->what();
    EXPECT_TRUE(r.events.empty());
  }
}

TEST(McapFaults, UnknownCompressionIsNamed) {
  const ScratchDir dir{"test_io_mcap"};
  const std::vector<Event> full = read_all(kMcap + "evt3_zstd.mcap").events;
  const Faulty f = read_damaged(dir, "evt3_zstd.mcap", "brotli.mcap", [](std::vector<char>& b, const auto& chunks) {
    // Chunk content: 3 u64 + u32 CRC, then the compression string (u32 length + "zstd").
    const std::uint64_t name_at = chunks[1] + 9 + 28 + 4;
    std::memcpy(b.data() + name_at, "zbr1", 4);
    return chunks[1];
  });
  expect_fault(f, full, "brotli.mcap", "chunk compressed with 'zbr1' (readable: none, zstd, lz4)");
}

/// The Footer's summary_start (the spec's layout: Footer = u8 op, u64 length,
/// u64 summary_start, u64 summary_offset_start, u32 summary CRC; then magic).
std::uint64_t summary_start(const std::vector<char>& b) {
  std::uint64_t v = 0;
  std::memcpy(&v, b.data() + b.size() - 8 - 29 + 9, 8);
  return v;
}

// One byte of the Header changed after the writer computed the CRCs: no chunk
// CRC covers it; the DataEnd's data-section CRC does. Every event is kept
// (the fault is found at the end of the data section); a CRC of 0 is not checked.
TEST(McapFaults, DataSectionCrcMismatchIsReportedAtTheDataEndAfterEveryEvent) {
  const ScratchDir dir{"test_io_mcap"};
  for (const char* bag : {"evt3", "mono"}) {
    const ReadAll intact = read_all(kMcap + bag + "_zstd.mcap");
    ASSERT_FALSE(intact.error) << intact.error->what();
    const std::string path = kMcap + bag + "_zstd_datacrc.mcap";
    const ReadAll r = read_all(path);
    ASSERT_TRUE(r.error) << path;
    const std::string what = r.error->what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find("MCAP data section CRC mismatch"), std::string::npos) << what;
    std::vector<char> b = bytes_of(path);
    const std::uint64_t data_end = summary_start(b) - 13;  // DataEnd: 9-byte prefix + u32 CRC
    ASSERT_EQ(b[data_end], 0x0F);
    EXPECT_EQ(r.error->byte_offset(), static_cast<std::int64_t>(data_end)) << what;
    EXPECT_TRUE(same_events(r.events, intact.events)) << r.events.size() << " of " << intact.events.size();
    std::memset(b.data() + data_end + 9, 0, 4);  // CRC 0: not given
    const std::string unchecked = dir.file(std::string(bag) + "_datacrc0.mcap");
    write_bytes(unchecked, b);
    const ReadAll plain = read_all(unchecked);
    EXPECT_FALSE(plain.error) << plain.error->what();
    EXPECT_TRUE(same_events(plain.events, intact.events));
  }
}

// One byte of the summary (the last ChunkIndex) changed after the CRCs: the
// summary is not trusted (topics come from a scan of the data section), every
// event is read, then the fault names the summary's offset; CRC 0: not checked.
TEST(McapFaults, SummaryCrcMismatchIsReportedAfterEveryEvent) {
  const ScratchDir dir{"test_io_mcap"};
  for (const char* bag : {"evt3", "mono"}) {
    const ReadAll intact = read_all(kMcap + bag + "_zstd.mcap");
    const std::string path = kMcap + bag + "_zstd_summarycrc.mcap";
    const ReadAll r = read_all(path);
    ASSERT_TRUE(r.error) << path;
    const std::string what = r.error->what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find("MCAP summary CRC mismatch"), std::string::npos) << what;
    std::vector<char> b = bytes_of(path);
    EXPECT_EQ(r.error->byte_offset(), static_cast<std::int64_t>(summary_start(b))) << what;
    EXPECT_TRUE(same_events(r.events, intact.events)) << r.events.size() << " of " << intact.events.size();
    ASSERT_EQ(r.streams.size(), intact.streams.size());  // from the scan, with the same counts
    for (std::size_t i = 0; i < r.streams.size(); ++i) {
      EXPECT_EQ(r.streams[i].name, intact.streams[i].name);
      EXPECT_EQ(r.streams[i].messages, intact.streams[i].messages) << r.streams[i].name;
    }
    std::memset(b.data() + b.size() - 8 - 4, 0, 4);  // the Footer's summary CRC 0: not given
    const std::string unchecked = dir.file(std::string(bag) + "_summarycrc0.mcap");
    write_bytes(unchecked, b);
    const ReadAll plain = read_all(unchecked);
    EXPECT_FALSE(plain.error) << plain.error->what();
    EXPECT_TRUE(same_events(plain.events, intact.events));
  }
}

// A frame cut short inside a several-frame chunk is a corrupt chunk (the
// events of the chunks before it kept), not a short read.
TEST(McapFaults, CutFrameOfASeveralFrameChunkIsCorrupt) {
  const ScratchDir dir{"test_io_mcap"};
  for (const char* how : {"zstd", "lz4"}) {
    const std::string source = std::string("evt3_") + how + "_frames.mcap";
    const std::vector<Event> full = read_all(kMcap + source).events;
    const std::string name = std::string("cutframe_") + how + ".mcap";
    const Faulty f = read_damaged(dir, source, name, [](std::vector<char>& b, const auto& chunks) {
      // Chunk content: 3 u64, u32 CRC, compression string (u32 length + chars), u64 length, frames.
      std::uint32_t name_len = 0;
      std::memcpy(&name_len, b.data() + chunks[2] + 9 + 28, 4);
      const std::uint64_t length_at = chunks[2] + 9 + 28 + 4 + name_len;
      std::uint64_t len = 0;
      std::memcpy(&len, b.data() + length_at, 8);
      // 8 bytes fewer: the last frame loses its end (the chunk record keeps
      // its length; the 8 bytes become trailing content, ignored).
      len -= 8;
      std::memcpy(b.data() + length_at, &len, 8);
      return chunks[2];
    });
    expect_fault(f, full, name, "corrupt " + std::string(how) + " chunk");
  }
}

// A file cut (or corrupt) before the record that names its event topic: the
// fault at its offset, not "no event topic in the bag" (a review's finding:
// any cut inside the first chunk of evt3_zstd.mcap, bytes 48-50188, said that;
// with --topic, "no topic '/event_camera/events' in the bag").
TEST(McapFaults, ACutBeforeTheEventTopicIsTheFaultNotAMissingTopic) {
  const ScratchDir dir{"test_io_mcap"};
  std::vector<char> b = bytes_of(kMcap + "evt3_zstd.mcap");
  const std::vector<std::uint64_t> chunks = chunk_offsets(b);
  ASSERT_FALSE(chunks.empty());
  b.resize(chunks[0] + 100);  // inside the first chunk
  const std::string path = dir.file("cut_first.mcap");
  write_bytes(path, b);
  for (const std::string& topic : {std::string(), std::string("/event_camera/events")}) {
    SCOPED_TRACE(topic);
    io::ReaderOptions options;
    options.topic = topic;
    try {
      io::open_event_reader(path, options);
      ADD_FAILURE() << "opened";
    } catch (const io::ReadError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("runs past the end of the file (truncated)"), std::string::npos) << message;
      EXPECT_EQ(e.byte_offset(), static_cast<std::int64_t>(chunks[0])) << message;
    }
  }
}

TEST(McapFaults, NotAnMcapFileAndACutHeaderAreRefusedAtOpen) {
  const ScratchDir dir{"test_io_mcap"};
  const std::string path = dir.file("text.mcap");
  write_bytes(path, {'h', 'e', 'l', 'l', 'o', '\n'});
  const std::string text_error = evlife::test::open_error(path);
  EXPECT_NE(text_error.find("not an MCAP file"), std::string::npos) << text_error;
  const std::string magic_only = dir.file("magic.mcap");
  write_bytes(magic_only, {'\x89', 'M', 'C', 'A', 'P', '0', '\r', '\n', '\x01'});
  const std::string cut_error = evlife::test::open_error(magic_only);
  EXPECT_NE(cut_error.find("truncated inside its Header record"), std::string::npos) << cut_error;
}

}  // namespace

// A Chunk whose opcode byte is damaged: into a Footer or DataEnd it ended the
// read there, into 0x00, a reserved or a private opcode it was skipped with
// its messages; exit 0 each time, even where every CRC was present (a Footer
// ended the stream before the DataEnd CRC). Now an error at the chunk after
// the events before it, or, for the unknown opcodes the specification says to
// skip, a skipped record counted and the summary's Statistics count not met.
TEST(McapFaults, AChunkWhoseOpcodeIsDamagedIsAnErrorNotAnEnd) {
  const ScratchDir dir{"test_io_mcap"};
  const std::vector<Event> full = read_all(kMcap + "evt3_none.mcap").events;
  const auto damaged = [&](const char* name, char opcode) {
    return read_damaged(dir, "evt3_none.mcap", name, [opcode](std::vector<char>& b, const auto& chunks) {
      b[chunks[2]] = opcode;
      return chunks[2];
    });
  };
  expect_fault(damaged("footer_op.mcap", '\x02'), full, "footer_op.mcap", "MCAP Footer record inside the data section");
  expect_fault(damaged("header_op.mcap", '\x01'), full, "header_op.mcap", "a second Header in the data section");
  const Faulty data_end = damaged("data_end_op.mcap", '\x0f');
  ASSERT_TRUE(data_end.r.error);
  EXPECT_EQ(data_end.r.error->byte_offset(), static_cast<std::int64_t>(data_end.chunk_at)) << data_end.r.error->what();
  EXPECT_EQ(data_end.r.events.size(), data_end.expected_events);

  // An unknown opcode is skipped as the specification says, and counted; here the data CRC fails.
  const Faulty skipped = damaged("private_op.mcap", '\xf9');
  ASSERT_TRUE(skipped.r.error);
  EXPECT_GT(skipped.r.events.size(), skipped.expected_events);  // the chunks after it, then the DataEnd CRC
  EXPECT_LT(skipped.r.events.size(), full.size());
  const auto private_records = [](const std::string& path) {
    const std::unique_ptr<io::EventReader> reader = io::open_event_reader(path);
    std::vector<Event> block(1 << 16);
    try {
      while (reader->read(block) > 0) {
      }
    } catch (const io::ReadError&) {
    }
    for (const auto& k : reader->skipped_record_kinds())
      if (k.kind == "mcap-record-of-an-unknown-opcode") return k.count;
    return std::uint64_t{0};
  };
  EXPECT_EQ(private_records(dir.file("private_op.mcap")), 1u);
  // Without a data CRC (the mcap library's default): the summary's Statistics count is not met.
  const std::vector<char> mono = bytes_of(std::string(EVLIFE_SOURCE_DIR) + "/tests/fuzz/corpus/mcap/mono_none.mcap");
  ASSERT_EQ(mono.at(48), '\x06');  // its only Chunk
  for (const char opcode : {'\x00', '\x42', '\xf9'}) {
    std::vector<char> b = mono;
    b[48] = opcode;
    const std::string no_crc = dir.file("unknown_op_no_crc.mcap");
    write_bytes(no_crc, b);
    const ReadAll r = read_all(no_crc);
    ASSERT_TRUE(r.error) << r.events.size() << " events, no error";
    EXPECT_NE(std::string(r.error->what()).find("MCAP summary's Statistics count 2 messages on topic"), std::string::npos)
        << r.error->what();
    EXPECT_EQ(r.events.size(), 0u);
    EXPECT_EQ(private_records(no_crc), 1u);
  }
}

// A Statistics record whose channel_message_counts map is empty ("this
// statistic is not available", the spec): the topics are counted by a scan,
// and nothing is checked against the empty map (an early version of the
// check refused the file: "count 0 messages …, the data section holds 2").
TEST(McapReader, StatisticsWithoutChannelCountsAreNotAFault) {
  const ScratchDir dir{"test_io_mcap"};
  std::vector<char> b = bytes_of(std::string(EVLIFE_SOURCE_DIR) + "/tests/fuzz/corpus/mcap/mono_none.mcap");
  const std::size_t footer = b.size() - 8 - 29;
  ASSERT_EQ(b[footer], '\x02');
  std::uint64_t summary_start = 0, summary_offset_start = 0;
  std::memcpy(&summary_start, b.data() + footer + 9, 8);
  std::memcpy(&summary_offset_start, b.data() + footer + 17, 8);
  const std::uint64_t end = summary_offset_start != 0 ? summary_offset_start : footer;
  bool emptied = false;
  for (std::uint64_t pos = summary_start; pos < end;) {
    std::uint64_t len = 0;
    std::memcpy(&len, b.data() + pos + 1, 8);
    if (b[pos] == '\x0b') {  // Statistics: its map's byte length after 42 bytes of counts and times
      const std::uint32_t none = 0;
      std::memcpy(b.data() + pos + 9 + 42, &none, 4);
      emptied = true;
    }
    pos += 9 + len;
  }
  ASSERT_TRUE(emptied);
  const std::uint32_t no_crc = 0;
  std::memcpy(b.data() + footer + 25, &no_crc, 4);  // the summary CRC, which the change breaks
  const std::string path = dir.file("empty_statistics.mcap");
  write_bytes(path, b);
  const ReadAll r = read_all(path);
  ASSERT_FALSE(r.error) << r.error->what();
  EXPECT_EQ(r.events.size(), 100u);
}
