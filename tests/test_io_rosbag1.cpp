// ROS 1 bags (v2.0) written by Debian's python3-rosbag (tests/data/ros1/
// make_bags.py) from the shared ROS 2 bags' messages: uncompressed, bz2 and
// lz4 chunks decode to the same events as the .db3 they come from; topic
// choice, `info` streams, corrupt chunks and unknown compression.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
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

TEST_F(Rosbag1Faults, UnknownCompressionTruncatedAndNotIndexed) {
  std::vector<char> bytes = load(kBags + "evt3_lz4.bag");
  for (const std::size_t at : find_all(bytes, "compression=lz4")) bytes[at + 12] = 'z';
  ReadAll r = read_all(save("zz4.bag", bytes));
  ASSERT_TRUE(r.error);
  EXPECT_NE(std::string(r.error->what()).find("'zz4'"), std::string::npos) << r.error->what();
  // Cut in half: the index at the end is gone.
  const std::vector<char> full = load(kBags + "evt3_none.bag");
  const std::string cut = save("cut.bag", std::vector<char>(full.begin(), full.begin() + static_cast<long>(full.size() / 2)));
  const std::string cut_error = evlife::test::open_error(cut);
  EXPECT_NE(cut_error.find("not indexed"), std::string::npos) << cut_error;
  // Cut where the index begins (it read no index, then "no event topic"), and inside it.
  const std::size_t field = find_all(full, "index_pos=").at(0) + 10;
  std::uint64_t index_pos = 0;
  std::memcpy(&index_pos, full.data() + field, sizeof index_pos);
  ASSERT_LT(index_pos, full.size());
  const auto cut_at = [&](std::size_t size) {
    return evlife::test::open_error(save("cut_at.bag", std::vector<char>(full.begin(), full.begin() + static_cast<long>(size))));
  };
  const std::string at_index = cut_at(index_pos);
  EXPECT_NE(at_index.find("not indexed"), std::string::npos) << at_index;
  const std::string in_index = cut_at(index_pos + 30);
  EXPECT_NE(in_index.find("(in the bag's index, after its chunks: a file cut short; run `rosbag reindex` on it)"),
            std::string::npos)
      << in_index;
}

}  // namespace
