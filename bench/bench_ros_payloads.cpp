// Decode speed of the ROS event messages (events/s, one core): every message
// of each shared rosbag2 bag is loaded into memory once, then decoded per
// iteration by ros::MessageDecoder (CDR parse + payload: evt3 / libcaer /
// mono), the container's cost left out. "bag" = the whole rosbag2 reader
// (sqlite3 + decode + µs conversion) through open_unchecked_event_reader;
// "mcap" = the same bag repackaged as MCAP (none / zstd / lz4 chunks; files
// written by the tests' make_mcap.py: `cmake --build build --target
// evlife_mcap_test_files`), the whole MCAP reader (read + decompress + CRC +
// decode + µs conversion).
//   ./build/bench/bench_ros_payloads --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "evlife/io/event_reader.h"
#include "ros_messages.h"
#include "rosbag2_messages.h"

namespace {

namespace ros = evlife::io::ros;

const std::string kBags = std::string(EVLIFE_SHARED_DATA_DIR) + "/rosbag/";

struct Loaded {
  ros::MessageKind kind;
  std::vector<std::vector<std::uint8_t>> messages;
};

Loaded load(const std::string& bag_path) {
  ros::Rosbag2Messages bag(bag_path);
  const ros::TopicInfo topic = bag.topics().at(0);
  Loaded l{ros::message_kind(topic.type), {}};
  bag.select(topic.name);
  ros::Rosbag2Messages::Message m;
  while (bag.next(m)) l.messages.emplace_back(m.data.begin(), m.data.end());
  return l;
}

void decode_messages(benchmark::State& state, const std::string& bag) {
  const Loaded loaded = load(kBags + bag);
  std::vector<ros::RosEvent> events;
  std::int64_t total = 0;
  for (auto _ : state) {
    ros::MessageDecoder decoder(loaded.kind);  // evt3 state starts afresh per pass
    for (const auto& m : loaded.messages) {
      if (decoder.decode(m, events)) state.SkipWithError("decode fault");
      total += static_cast<std::int64_t>(events.size());
      benchmark::DoNotOptimize(events.data());
    }
  }
  state.SetItemsProcessed(total);
}

void read_bag(benchmark::State& state, const std::string& bag) {
  std::vector<evlife::Event> batch(1 << 16);
  std::int64_t total = 0;
  for (auto _ : state) {
    auto reader = evlife::io::open_unchecked_event_reader(kBags + bag);
    while (const std::size_t n = reader->read(batch)) total += static_cast<std::int64_t>(n);
  }
  state.SetItemsProcessed(total);
}

void read_mcap(benchmark::State& state, const std::string& file) {
  const std::string path = std::string(EVLIFE_MCAP_TEST_DIR) + "/" + file;
  if (!std::filesystem::exists(path)) {
    state.SkipWithError("no MCAP test file: cmake --build build --target evlife_mcap_test_files");
    return;
  }
  std::vector<evlife::Event> batch(1 << 16);
  std::int64_t total = 0;
  for (auto _ : state) {
    auto reader = evlife::io::open_unchecked_event_reader(path);
    while (const std::size_t n = reader->read(batch)) total += static_cast<std::int64_t>(n);
  }
  state.SetItemsProcessed(total);
}

BENCHMARK_CAPTURE(decode_messages, evt3, std::string("test_data_evt3_trigger"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(decode_messages, libcaer, std::string("test_data_libcaer_rollover"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(decode_messages, mono, std::string("test_data_mono_cd"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(read_bag, evt3, std::string("test_data_evt3_trigger"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_bag, libcaer, std::string("test_data_libcaer_rollover"))->Unit(benchmark::kMillisecond);

BENCHMARK_CAPTURE(read_mcap, evt3_none, std::string("evt3_none.mcap"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_mcap, evt3_zstd, std::string("evt3_zstd.mcap"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_mcap, evt3_lz4, std::string("evt3_lz4.mcap"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_mcap, libcaer_none, std::string("libcaer_none.mcap"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_mcap, libcaer_zstd, std::string("libcaer_zstd.mcap"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_mcap, libcaer_lz4, std::string("libcaer_lz4.mcap"))->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
