// ROS 1 bags (v2.0) written by Debian's python3-rosbag (tests/data/ros1/
// make_bags.py) from the shared ROS 2 bags' messages: uncompressed, bz2 and
// lz4 chunks decode to the same events as the .db3 they come from; topic
// choice, `info` streams, corrupt chunks and unknown compression; bags
// without a usable index (cut, or a recording that stopped before closing).
#include <gtest/gtest.h>
#include <lz4frame.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <tuple>
#include <vector>

#include "evlife/io/event_reader.h"
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

const std::string kBags = std::string(EVLIFE_SOURCE_DIR) + "/tests/data/ros1/";
const std::string kShared = std::string(EVLIFE_SHARED_DATA_DIR) + "/rosbag/";

using evlife::test::ReadAll;

ReadAll read_all(const std::string& path) { return evlife::test::read_all(path, {}, 999); }

/// The events of the first `limit` messages of a ROS 2 bag, floored to µs.
std::vector<Event> db3_events(const std::string& bag_path, std::size_t limit) {
  const evlife::test::RosMessages messages = evlife::test::decode_db3(bag_path);
  std::vector<Event> all;
  for (std::size_t i = 0; i < limit && i < messages.size(); ++i)
    for (const ros::RosEvent& e : messages[i]) all.push_back(Event{e.t_ns / 1000, e.x, e.y, e.p});
  return all;
}

bool same(const std::vector<Event>& a, const std::vector<Event>& b, std::size_t n) {
  if (a.size() < n || b.size() < n) return false;
  return std::memcmp(a.data(), b.data(), n * sizeof(Event)) == 0;
}

TEST(Rosbag1, Evt3PacketsInEveryChunkCompressionMatchTheDb3) {
  const std::vector<Event> reference = db3_events(kShared + "test_data_evt3_trigger", 30);
  ASSERT_GT(reference.size(), 10'000u);
  for (const std::string c : {"none", "bz2", "lz4"}) {
    const ReadAll r = read_all(kBags + "evt3_" + c + ".bag");
    ASSERT_FALSE(r.error) << c << ": " << r.error->what();
    EXPECT_EQ(r.format, "rosbag1");
    EXPECT_EQ(r.sensor, (SensorSize{1280, 720}));
    ASSERT_EQ(r.events.size(), reference.size()) << c;
    EXPECT_TRUE(same(r.events, reference, reference.size())) << c;
  }
}

// iniVation's dv-ros driver records dv_ros_msgs/EventArray: dvs_msgs' layout under its own
// name ("no event topic in the bag" before).
TEST(Rosbag1, DvRosEventArrayReadsAsDvsMsgs) {
  const ReadAll dvs = read_all(kBags + "mono_dvs.bag");
  const ReadAll r = read_all(kBags + "mono_dv_ros.bag");
  ASSERT_FALSE(r.error) << r.error->what();
  EXPECT_EQ(r.sensor, (SensorSize{640, 480}));
  ASSERT_EQ(r.events.size(), 100u);
  EXPECT_TRUE(same(r.events, dvs.events, 100));
}

TEST(Rosbag1, DvsEventArrayMatchesTheMonoDb3AndSkipsOtherTopics) {
  const ReadAll reference = read_all(kShared + "test_data_mono_cd");
  const ReadAll r = read_all(kBags + "mono_dvs.bag");
  ASSERT_FALSE(r.error) << r.error->what();
  EXPECT_EQ(r.sensor, (SensorSize{640, 480}));
  ASSERT_EQ(r.events.size(), 100u);
  EXPECT_TRUE(same(r.events, reference.events, 100));
  ASSERT_EQ(r.streams.size(), 2u);
  const auto dvs = std::find_if(r.streams.begin(), r.streams.end(), [](const auto& s) { return s.name == "/dvs/events"; });
  ASSERT_NE(dvs, r.streams.end());
  EXPECT_TRUE(dvs->read);
  EXPECT_EQ(dvs->type, "dvs_msgs/EventArray");
  EXPECT_EQ(dvs->messages, 2u);
}

class Rosbag1Faults : public ::testing::Test {
 protected:
  static std::vector<char> load(const std::string& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
  }
  std::string save(const std::string& name, const std::vector<char>& bytes) const { return dir_.save(name, bytes); }
  /// Offsets of `text` in `bytes`.
  static std::vector<std::size_t> find_all(const std::vector<char>& bytes, const std::string& text) {
    std::vector<std::size_t> at;
    for (auto it = bytes.begin(); (it = std::search(it, bytes.end(), text.begin(), text.end())) != bytes.end(); ++it)
      at.push_back(static_cast<std::size_t>(it - bytes.begin()));
    return at;
  }
  const evlife::test::ScratchDir dir_{"test_io_rosbag1"};
};

TEST_F(Rosbag1Faults, CorruptSecondChunkKeepsTheFirstChunksEvents) {
  const std::vector<Event> reference = db3_events(kShared + "test_data_evt3_trigger", 30);
  std::vector<char> bytes = load(kBags + "evt3_bz2.bag");
  const auto chunks = find_all(bytes, "compression=bz2");
  ASSERT_GE(chunks.size(), 2u);
  bytes[chunks[1] + 200] = static_cast<char>(bytes[chunks[1] + 200] ^ 0x5A);  // inside the bz2 data
  const std::string path = save("bad.bag", bytes);
  const ReadAll r = read_all(path);
  ASSERT_TRUE(r.error);
  const std::string what = r.error->what();
  EXPECT_NE(what.find(path), std::string::npos) << what;
  EXPECT_NE(what.find("corrupt ROS 1 chunk"), std::string::npos) << what;
  EXPECT_GT(r.events.size(), 0u);
  EXPECT_LT(r.events.size(), reference.size());
  EXPECT_TRUE(same(r.events, reference, r.events.size()));
}

TEST_F(Rosbag1Faults, UnknownCompressionIsNamed) {
  std::vector<char> bytes = load(kBags + "evt3_lz4.bag");
  for (const std::size_t at : find_all(bytes, "compression=lz4")) bytes[at + 12] = 'z';
  const ReadAll r = read_all(save("zz4.bag", bytes));
  ASSERT_TRUE(r.error);
  EXPECT_NE(std::string(r.error->what()).find("'zz4'"), std::string::npos) << r.error->what();
}

/// A closed bag cut short: the chunks before the cut are read without the
/// index, then the cut is the error, naming the file and its offset.
TEST_F(Rosbag1Faults, ACutBagDeliversItsWholeChunksThenTheCut) {
  const std::vector<Event> reference = db3_events(kShared + "test_data_evt3_trigger", 30);
  const std::vector<char> full = load(kBags + "evt3_none.bag");
  const auto read_cut = [&](std::size_t size) {
    return read_all(save("cut.bag", std::vector<char>(full.begin(), full.begin() + static_cast<long>(size))));
  };
  // In half: inside a chunk.
  const ReadAll half = read_cut(full.size() / 2);
  ASSERT_TRUE(half.error);
  EXPECT_NE(std::string(half.error->what()).find("cut.bag"), std::string::npos) << half.error->what();
  EXPECT_NE(half.error->reason().find("runs past the end of the file"), std::string::npos) << half.error->what();
  EXPECT_GT(half.error->byte_offset(), 0);
  EXPECT_LT(half.error->byte_offset(), static_cast<std::int64_t>(full.size() / 2));
  EXPECT_GT(half.events.size(), 0u);
  EXPECT_LT(half.events.size(), reference.size());
  EXPECT_TRUE(same(half.events, reference, half.events.size()));

  const std::size_t field = find_all(full, "index_pos=").at(0) + 10;
  std::uint64_t index_pos = 0;
  std::memcpy(&index_pos, full.data() + field, sizeof index_pos);
  ASSERT_LT(index_pos, full.size());
  // Where the index begins, and inside it: every chunk is whole, every event read.
  const ReadAll at_index = read_cut(index_pos);
  ASSERT_TRUE(at_index.error);
  EXPECT_NE(at_index.error->reason().find("its index, at offset " + std::to_string(index_pos) + ", is not in the file"),
            std::string::npos)
      << at_index.error->what();
  EXPECT_EQ(at_index.error->byte_offset(), static_cast<std::int64_t>(index_pos));
  const ReadAll in_index = read_cut(index_pos + 30);
  ASSERT_TRUE(in_index.error);
  EXPECT_NE(std::string(in_index.error->what())
                .find("(in the bag's index, after its chunks: a file cut short or corrupt; the chunks were read without it)"),
            std::string::npos)
      << in_index.error->what();
  for (const ReadAll* r : {&at_index, &in_index}) {
    ASSERT_EQ(r->events.size(), reference.size());
    EXPECT_TRUE(same(r->events, reference, reference.size()));
    ASSERT_EQ(r->streams.size(), 1u);
    EXPECT_EQ(r->streams[0].messages, 30u);
  }
}

/// What a recording that stopped before closing its bag leaves (Debian's
/// python3-rosbag, flushed before close(): make_bags.py): index_pos 0, no
/// index, the last chunk with placeholder sizes. Read as `rosbag reindex`
/// would: every message, no error.
TEST_F(Rosbag1Faults, AnInterruptedRecordingReadsWholeWithoutItsIndex) {
  const std::vector<Event> reference = db3_events(kShared + "test_data_evt3_trigger", 30);
  const std::string active = kBags + "evt3_interrupted.bag.active";
  const ReadAll r = read_all(active);
  ASSERT_FALSE(r.error) << r.error->what();
  EXPECT_EQ(r.format, "rosbag1");
  EXPECT_EQ(r.sensor, (SensorSize{1280, 720}));
  ASSERT_EQ(r.events.size(), reference.size());
  EXPECT_TRUE(same(r.events, reference, reference.size()));
  ASSERT_EQ(r.streams.size(), 1u);
  EXPECT_EQ(r.streams[0].name, "/event_camera/events");
  EXPECT_EQ(r.streams[0].type, "event_camera_msgs/EventPacket");
  EXPECT_EQ(r.streams[0].messages, 30u);

  // The open chunk: its header's placeholder sizes, then its records to the file's end.
  const std::vector<char> bytes = load(active);
  const std::size_t open_chunk = find_all(bytes, "compression=none").back();
  ASSERT_GT(open_chunk, bytes.size() / 2);
  // Cut inside its last record: the records before are read, then the cut.
  const ReadAll cut = read_all(save("cut.bag.active", std::vector<char>(bytes.begin(), bytes.end() - 100)));
  ASSERT_TRUE(cut.error);
  EXPECT_NE(cut.error->reason().find("cut inside a record of the chunk being written when the recording stopped"),
            std::string::npos)
      << cut.error->what();
  EXPECT_GT(cut.error->byte_offset(), static_cast<std::int64_t>(open_chunk));
  EXPECT_LT(cut.events.size(), reference.size());
  EXPECT_GT(cut.events.size(), reference.size() / 2);  // the closed chunks and the open one's first records
  EXPECT_TRUE(same(cut.events, reference, cut.events.size()));
  // Stopped right after that chunk's header: the closed chunks, no error (nothing on disk unread).
  const std::size_t header_end = static_cast<std::size_t>(
      std::search(bytes.begin() + static_cast<long>(open_chunk), bytes.end(), std::begin("size="), std::end("size=") - 1) -
      bytes.begin()) + 5 + 4 + 4;  // the size field, then the data length
  const ReadAll empty_open = read_all(save("empty.bag.active", std::vector<char>(bytes.begin(), bytes.begin() + static_cast<long>(header_end))));
  ASSERT_FALSE(empty_open.error) << empty_open.error->what();
  EXPECT_LT(empty_open.events.size(), cut.events.size());
  EXPECT_GT(empty_open.events.size(), 0u);
  EXPECT_TRUE(same(empty_open.events, reference, empty_open.events.size()));
  // An open chunk of a compression no reader knows: an error after the closed chunks' events.
  std::vector<char> compressed = bytes;
  std::memcpy(compressed.data() + open_chunk + 12, "zstd", 4);
  const ReadAll unreadable = read_all(save("zstd.bag.active", compressed));
  ASSERT_TRUE(unreadable.error);
  EXPECT_NE(unreadable.error->reason().find("ROS 1 chunk compressed with 'zstd'"), std::string::npos)
      << unreadable.error->what();
  // Its record starts with the header length, then the field "op=\x05" (and its length) before this one's length.
  EXPECT_EQ(unreadable.error->byte_offset(), static_cast<std::int64_t>(open_chunk) - 4 - 4 - 4 - 4);
  EXPECT_EQ(unreadable.events.size(), empty_open.events.size());
  EXPECT_TRUE(same(unreadable.events, reference, unreadable.events.size()));
}

/// `closed` as a recorder that streams compressed chunks to disk (librosbag's
/// ChunkedFile) leaves it when killed inside its chunk number `chunk` (kLast:
/// the last): index_pos 0, that chunk's sizes the placeholders (0), `keep`
/// bytes of its data (kHalf: half of it), nothing after.
constexpr std::size_t kHalf = SIZE_MAX;
constexpr std::size_t kLast = SIZE_MAX;
std::vector<char> stopped_inside_chunk(const std::vector<char>& closed, std::size_t chunk, std::size_t keep) {
  const auto u32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    std::memcpy(&v, closed.data() + at, 4);
    return std::size_t{v};
  };
  const auto field_at = [&](std::size_t header, std::size_t len, const std::string& name) {
    for (std::size_t at = header; at < header + len; at += 4 + u32(at))
      if (std::string_view(closed.data() + at + 4, name.size()) == name) return at + 4 + name.size();
    return std::string::npos;
  };
  const std::size_t bag_header = 13;
  const std::size_t index_pos_at = field_at(bag_header + 4, u32(bag_header), "index_pos=");
  std::uint64_t index_pos = 0;
  std::memcpy(&index_pos, closed.data() + index_pos_at, 8);
  std::size_t last_chunk = 0;
  std::size_t chunks = 0;
  for (std::size_t at = bag_header; at < index_pos && chunks <= chunk; at += 8 + u32(at) + u32(at + 4 + u32(at)))
    if (field_at(at + 4, u32(at), "op=") != std::string::npos && closed[field_at(at + 4, u32(at), "op=")] == 0x05) {
      last_chunk = at;
      ++chunks;
    }
  std::vector<char> bag(closed.begin(), closed.end());
  std::memset(bag.data() + index_pos_at, 0, 8);
  const std::size_t header_len = u32(last_chunk);
  std::memset(bag.data() + field_at(last_chunk + 4, header_len, "size="), 0, 4);
  const std::size_t data_len_at = last_chunk + 4 + header_len;
  std::memset(bag.data() + data_len_at, 0, 4);
  bag.resize(data_len_at + 4 + (keep == kHalf ? u32(data_len_at) / 2 : std::min(keep, u32(data_len_at))));
  return bag;
}

/// A recording with compressed chunks killed inside one: the records of its
/// whole bz2 / LZ4 blocks on disk are read, then the cut is the error; killed
/// before a block reached the file (the LZ4 frame's header only, or nothing),
/// the closed chunks are all there is, and no error.
TEST_F(Rosbag1Faults, ACompressedChunkCutShortKeepsItsWholeBlocks) {
  const std::vector<Event> reference = db3_events(kShared + "test_data_evt3_trigger", 30);
  for (const std::string c : {"bz2", "lz4"}) {
    const std::vector<char> closed = load(kBags + "evt3_" + c + ".bag");
    const ReadAll header_only = read_all(save("h.bag.active", stopped_inside_chunk(closed, kLast, c == "lz4" ? 7 : 0)));
    ASSERT_FALSE(header_only.error) << c << ": " << header_only.error->what();
    EXPECT_GT(header_only.events.size(), 0u) << c;
    EXPECT_LT(header_only.events.size(), reference.size()) << c;
    EXPECT_TRUE(same(header_only.events, reference, header_only.events.size())) << c;
    const ReadAll cut = read_all(save("cut.bag.active", stopped_inside_chunk(closed, kLast, kHalf)));
    ASSERT_TRUE(cut.error) << c;
    EXPECT_NE(cut.error->reason().find("cut inside the chunk being written when the recording stopped (" + c),
              std::string::npos)
        << cut.error->what();
    EXPECT_EQ(cut.events.size(), header_only.events.size()) << c << ": the chunk is one block, cut";
    EXPECT_TRUE(same(cut.events, reference, cut.events.size())) << c;
  }
  // An LZ4 chunk of several blocks (rosbag record --lz4 with large chunks): the
  // first chunk of the uncompressed bag (66 KiB) in 64 KiB LZ4 blocks, cut in its second.
  std::vector<char> bag = stopped_inside_chunk(load(kBags + "evt3_none.bag"), 0, SIZE_MAX - 1);
  const std::size_t open_chunk = find_all(bag, "compression=none").back();
  const std::size_t header_at = open_chunk - 16;  // header length, "op" field, this field's length
  std::uint32_t header_len = 0;
  std::memcpy(&header_len, bag.data() + header_at, 4);
  const std::vector<char> records(bag.begin() + static_cast<long>(header_at + 4 + header_len + 4), bag.end());
  ASSERT_GT(records.size(), 65536u);
  LZ4F_preferences_t prefs{};
  prefs.frameInfo.blockSizeID = LZ4F_max64KB;
  std::vector<char> frame(LZ4F_compressFrameBound(records.size(), &prefs));
  frame.resize(LZ4F_compressFrame(frame.data(), frame.size(), records.data(), records.size(), &prefs));
  bag.resize(header_at);
  const std::string fields[] = {std::string("op=\x05", 4), "compression=lz4", std::string("size=\0\0\0\0", 9)};
  std::uint32_t len = 0;
  for (const std::string& f : fields) len += 4 + static_cast<std::uint32_t>(f.size());
  const auto put_u32 = [&](std::uint32_t v) { bag.insert(bag.end(), reinterpret_cast<char*>(&v), reinterpret_cast<char*>(&v) + 4); };
  put_u32(len);
  for (const std::string& f : fields) {
    put_u32(static_cast<std::uint32_t>(f.size()));
    bag.insert(bag.end(), f.begin(), f.end());
  }
  put_u32(0);  // the placeholder data length
  bag.insert(bag.end(), frame.begin(), frame.end() - 50);  // inside the second, last block (2 KiB of records)
  const ReadAll blocks = read_all(save("blocks.bag.active", bag));
  ASSERT_TRUE(blocks.error);
  EXPECT_NE(blocks.error->reason().find("the records of its whole lz4 blocks were read"), std::string::npos)
      << blocks.error->what();
  EXPECT_GT(blocks.events.size(), 0u) << "the first block's records";
  EXPECT_LT(blocks.events.size(), reference.size());
  EXPECT_TRUE(same(blocks.events, reference, blocks.events.size()));
}

/// A scan that stops at a fault before any connection: that fault, with its
/// offset (not "no event topic"); a bag never closed before its first message.
TEST_F(Rosbag1Faults, AFaultBeforeAnyTopicIsTheError) {
  const std::vector<char> full = load(kBags + "evt3_none.bag");
  const std::string cut = evlife::test::open_error(save("first.bag", std::vector<char>(full.begin(), full.begin() + 5000)));
  EXPECT_NE(cut.find("runs past the end of the file (byte offset "), std::string::npos) << cut;
  // Cut right after the bag header record, at a record boundary: no chunk at all.
  std::uint32_t header_len = 0, data_len = 0;
  std::memcpy(&header_len, full.data() + 13, 4);
  std::memcpy(&data_len, full.data() + 13 + 4 + header_len, 4);
  const std::size_t first_record = 13 + 8 + header_len + data_len;
  const std::string no_chunk =
      evlife::test::open_error(save("none.bag", std::vector<char>(full.begin(), full.begin() + static_cast<long>(first_record))));
  EXPECT_NE(no_chunk.find("is not in the file"), std::string::npos) << no_chunk;
  const std::vector<char> active = load(kBags + "evt3_interrupted.bag.active");
  const std::size_t first_chunk = find_all(active, "compression=none").at(0);
  const std::string header_only = evlife::test::open_error(
      save("empty.bag.active", std::vector<char>(active.begin(), active.begin() + static_cast<long>(first_chunk) - 16)));
  EXPECT_NE(header_only.find("stopped before its first message reached the file"), std::string::npos) << header_only;
}

/// A closed bag cut at a record boundary inside its index (the bag header's
/// conn_count and chunk_count tell): read from the chunks, then the error.
TEST_F(Rosbag1Faults, AnIndexCutAtARecordBoundaryIsNoticed) {
  const std::vector<Event> reference = db3_events(kShared + "test_data_evt3_trigger", 30);
  const std::vector<char> full = load(kBags + "evt3_none.bag");
  const std::size_t field = find_all(full, "index_pos=").at(0) + 10;
  std::uint64_t index_pos = 0;
  std::memcpy(&index_pos, full.data() + field, sizeof index_pos);
  // The index's first record: a connection record; cut right after it.
  std::uint32_t header_len = 0, data_len = 0;
  std::memcpy(&header_len, full.data() + index_pos, 4);
  std::memcpy(&data_len, full.data() + index_pos + 4 + header_len, 4);
  const std::size_t end = index_pos + 8 + header_len + data_len;
  ASSERT_LT(end, full.size());
  const ReadAll r = read_all(save("idx.bag", std::vector<char>(full.begin(), full.begin() + static_cast<long>(end))));
  ASSERT_TRUE(r.error);
  EXPECT_NE(r.error->reason().find("ROS 1 bag index ends after 1 of its 1 connection records and 0 of its"),
            std::string::npos)
      << r.error->what();
  ASSERT_EQ(r.events.size(), reference.size());
  EXPECT_TRUE(same(r.events, reference, reference.size()));
  ASSERT_EQ(r.streams.size(), 1u);
  EXPECT_EQ(r.streams[0].messages, 30u);  // counted in the chunks, not the cut index's 0
}

/// A corrupt record inside a closed chunk: the records before it are
/// delivered, with the index or without it (the scan counts what it delivers).
TEST_F(Rosbag1Faults, ACorruptRecordInAChunkStopsThereWithOrWithoutTheIndex) {
  std::vector<char> bytes = load(kBags + "evt3_none.bag");
  const std::size_t last_chunk = find_all(bytes, "compression=none").back() - 16;
  std::uint32_t header_len = 0, first_record_header = 0, first_record_data = 0;
  std::memcpy(&header_len, bytes.data() + last_chunk, 4);
  const std::size_t records = last_chunk + 8 + header_len;  // the chunk's data: its records
  std::memcpy(&first_record_header, bytes.data() + records, 4);
  std::memcpy(&first_record_data, bytes.data() + records + 4 + first_record_header, 4);
  const std::size_t second = records + 8 + first_record_header + first_record_data;
  const std::uint32_t absurd = 0x7fffffff;
  std::memcpy(bytes.data() + second, &absurd, 4);  // the second record's header length
  const ReadAll indexed = read_all(save("indexed.bag", bytes));
  ASSERT_TRUE(indexed.error);
  const std::size_t field = find_all(bytes, "index_pos=").at(0) + 10;
  std::uint64_t index_pos = 0;
  std::memcpy(&index_pos, bytes.data() + field, sizeof index_pos);
  bytes.resize(index_pos + 30);  // the index cut: the chunks are scanned
  const ReadAll scanned = read_all(save("scanned.bag", bytes));
  ASSERT_TRUE(scanned.error);
  EXPECT_NE(scanned.error->reason().find("corrupt record at byte"), std::string::npos) << scanned.error->what();
  EXPECT_GT(scanned.events.size(), 0u);
  ASSERT_EQ(scanned.events.size(), indexed.events.size());
  EXPECT_EQ(0, std::memcmp(scanned.events.data(), indexed.events.data(), scanned.events.size() * sizeof(Event)));
  ASSERT_EQ(scanned.streams.size(), 1u);
}

// A record whose op is damaged or gone was skipped with the messages it held:
// a chunk's (a whole chunk lost) or a message's, exit 0, nothing counted.
// Now the error at its offset, after the events before it.
TEST_F(Rosbag1Faults, ARecordOfAnotherOpOrNoneIsAnErrorNotSkipped) {
  const std::vector<char> good = load(kBags + "evt3_none.bag");
  const ReadAll whole = read_all(save("whole.bag", good));
  ASSERT_FALSE(whole.error) << whole.error->what();
  const auto ops = [&](char op) {  // the "op=" fields whose value is `op`
    std::vector<std::size_t> at;
    for (const std::size_t i : find_all(good, "op=")) if (good[i + 3] == op) at.push_back(i + 3);
    return at;
  };
  const std::vector<std::size_t> chunks = ops('\x05'), messages = ops('\x02');
  ASSERT_GE(chunks.size(), 2u);
  ASSERT_GE(messages.size(), 2u);
  for (const auto& [name, at, value, said] :
       {std::tuple{"chunk_op.bag", chunks[1], '\x0b', "op 0x0b where the chunks are"},
        std::tuple{"message_op.bag", messages[1], '\x09', "of a ROS 1 chunk: op 0x09"}}) {
    std::vector<char> bytes = good;
    bytes[at] = value;
    const ReadAll r = read_all(save(name, bytes));
    ASSERT_TRUE(r.error) << name << ": " << r.events.size() << " of " << whole.events.size() << " events, no error";
    EXPECT_NE(std::string(r.error->what()).find(said), std::string::npos) << r.error->what();
    EXPECT_LT(r.events.size(), whole.events.size());
    EXPECT_EQ(0, std::memcmp(r.events.data(), whole.events.data(), r.events.size() * sizeof(Event))) << name;
  }
}


// A damaged conn field hid messages: the index naming the event topic's
// connection by another number read 0 of 100 events, a message's conn
// changed to an unknown or to the other topic's connection lost it; exit 0
// each time. Now an error, after every event the chunks hold or those
// before the message.
TEST_F(Rosbag1Faults, AMessageNoConnectionRecordNamesIsAnErrorNotSkipped) {
  const std::vector<char> good = load(kBags + "mono_dvs.bag");  // /dvs/events: 2 messages of 50 events; /notes
  const ReadAll whole = read_all(save("whole.bag", good));
  ASSERT_FALSE(whole.error) << whole.error->what();
  ASSERT_EQ(whole.events.size(), 100u);
  const auto conn_value_after = [&](std::size_t at) {  // the value of the first conn= field after `at`
    for (const std::size_t i : find_all(good, "conn=")) if (i > at) return i + 5;
    return good.size();
  };
  std::uint64_t index_pos = 0;
  std::memcpy(&index_pos, good.data() + find_all(good, "index_pos=").at(0) + 10, sizeof index_pos);
  std::size_t index_connection = 0;  // the index's connection record of /dvs/events: op, topic, conn
  for (const std::size_t i : find_all(good, std::string("op=\x07", 4)))
    if (i > index_pos && std::string(good.data() + i + 8, 17) == "topic=/dvs/events") index_connection = i;
  ASSERT_GT(index_connection, 0u);
  const std::vector<std::size_t> messages = find_all(good, std::string("op=\x02", 4));
  ASSERT_EQ(messages.size(), 4u);  // /dvs/events, /notes, /dvs/events, /notes
  const std::size_t second_events_message = conn_value_after(messages[2]);
  ASSERT_EQ(good[second_events_message], 0);

  struct Case {
    const char* name;
    std::size_t at;
    char value;
    const char* said;
    std::size_t events;
  };
  for (const Case& c : {Case{"index_conn.bag", conn_value_after(index_connection), '\x7f',
                             "index counts 2 messages of connection 0, which none of its connection records names", 100},
                        Case{"message_conn_unknown.bag", second_events_message, '\x7f',
                             "message of connection 127, which no connection record names", 50},
                        Case{"message_conn_other.bag", second_events_message, '\x01',
                             "index counts 2 messages of connection 0 (topic /dvs/events), its chunks hold 1", 50}}) {
    std::vector<char> bytes = good;
    bytes[c.at] = c.value;
    const ReadAll r = read_all(save(c.name, bytes));
    ASSERT_TRUE(r.error) << c.name << ": " << r.events.size() << " of 100 events, no error";
    EXPECT_NE(std::string(r.error->what()).find(c.said), std::string::npos) << c.name << ": " << r.error->what();
    EXPECT_NE(std::string(r.error->what()).find(c.name), std::string::npos) << r.error->what();
    ASSERT_EQ(r.events.size(), c.events) << c.name;
    EXPECT_TRUE(same(r.events, whole.events, c.events)) << c.name;
  }
}

}  // namespace
