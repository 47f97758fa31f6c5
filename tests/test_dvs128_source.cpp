// The DVS128 camera through the whole engine: emulated camera (umockdev,
// real libusb path) -> Dvs128Source -> Engine -> augmented events. Expected
// events are worked out by hand from the wire format (axis flips, wraps,
// resets), never taken from the decoder. Runs under umockdev-wrapper.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <thread>
#include <vector>

#include "dvs128_emulator.h"
#include "evlife/algo/lifetime_estimator.h"
#include "evlife/engine/augmented_sink.h"
#include "evlife/engine/dvs128_source.h"
#include "evlife/engine/engine.h"

namespace {

using evlife::AugmentedEvent;
using evlife::Event;
using evlife::engine::CallbackSink;
using evlife::engine::Engine;
using evlife::engine::EngineOptions;
using evlife::engine::RunResult;
using evlife::engine::RunStatus;
using evlife::testing::dvs128_word;
using evlife::testing::kResetWord;
using evlife::testing::kSyncWordFlag;
using evlife::testing::kWrapWord;
using evlife::testing::UsbTestbed;
using evlife::testing::words_to_bytes;
using namespace std::chrono_literals;

// Collects the engine's output; thread-safe (called from the merger thread).
struct Collector {
  std::mutex mutex;
  std::vector<AugmentedEvent> events;
  std::atomic<std::size_t> count{0};
  std::chrono::microseconds delay_per_write{0};
  CallbackSink sink{[this](std::span<const AugmentedEvent> span) {
    if (delay_per_write.count() > 0) std::this_thread::sleep_for(delay_per_write);
    std::lock_guard lock(mutex);
    events.insert(events.end(), span.begin(), span.end());
    count.store(events.size());
  }};
};

template <typename Pred>
bool wait_until(Pred pred, std::chrono::milliseconds budget = 5000ms) {
  const auto deadline = std::chrono::steady_clock::now() + budget;
  while (!pred()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(1ms);
  }
  return true;
}

EngineOptions quiet_options() {
  EngineOptions o;
  o.workers = 1;
  o.stats_period_s = 0.0;
  return o;
}

TEST(Dvs128Source, KnownWordsBecomeAugmentedEventsWithWrapAndReset) {
  UsbTestbed bed;
  auto& cam = bed.add_dvs128();
  const std::vector<std::uint32_t> words = {
      kResetWord,                          // the camera's answer to 0xBB
      dvs128_word(0, 0, false, 100),       // -> x 127, y 127, ON, t 100
      dvs128_word(10, 20, true, 16000),    // -> x 117, y 107, OFF, t 16000
      kWrapWord,                           // +16384
      dvs128_word(5, 6, false, 50),        // -> x 122, y 121, ON, t 16434
      kSyncWordFlag | (60u << 16),         // sync: counted, not a pixel
      kWrapWord | kResetWord,              // both flags: a wrap (+16384)
      dvs128_word(127, 127, true, 10),     // -> x 0, y 0, OFF, t 32778
      kResetWord,                          // time restarts from the last event
      dvs128_word(64, 1, false, 5),        // -> x 63, y 126, ON, t 32783
      kWrapWord,                           // +16384 since the reset
      dvs128_word(1, 2, false, 0),         // -> x 126, y 125, ON, t 49162
  };
  const std::vector<Event> expected = {
      {100, 127, 127, 1},  {16000, 117, 107, -1}, {16434, 122, 121, 1},
      {32778, 0, 0, -1},   {32783, 63, 126, 1},   {49162, 126, 125, 1},
  };
  const auto bytes = words_to_bytes(words);
  // Three transfers, one boundary inside a word (byte 6).
  cam.push_packet({bytes.begin(), bytes.begin() + 6});
  cam.push_packet({bytes.begin() + 6, bytes.begin() + 30});
  cam.push_packet({bytes.begin() + 30, bytes.end()});

  auto source = evlife::engine::make_dvs128_source("dvs128");
  Collector out;
  const EngineOptions options = quiet_options();
  Engine engine(*source, &out.sink, options);
  RunResult result;
  std::thread runner([&] { result = engine.run(); });
  const bool all = wait_until([&] { return out.count.load() >= expected.size(); });
  engine.request_stop();
  runner.join();
  ASSERT_TRUE(all) << "got " << out.count.load() << " of " << expected.size();

  EXPECT_EQ(result.status, RunStatus::interrupted);
  ASSERT_EQ(out.events.size(), expected.size());
  evlife::LifetimeOptions lifetime = options.lifetime;
  lifetime.sensor = {128, 128};
  evlife::LifetimeEstimator reference(lifetime);
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const Event& got = out.events[i].event;
    EXPECT_EQ(got.t_us, expected[i].t_us) << i;
    EXPECT_EQ(got.x, expected[i].x) << i;
    EXPECT_EQ(got.y, expected[i].y) << i;
    EXPECT_EQ(got.p, expected[i].p) << i;
    const AugmentedEvent ref = reference.process(expected[i]);
    EXPECT_EQ(out.events[i].lifetime_us, ref.lifetime_us) << i;
  }
  EXPECT_EQ(source->decoder_counters().sync_events, 1u);
  EXPECT_EQ(source->decoder_counters().wraps, 3u);
  EXPECT_EQ(source->decoder_counters().resets, 2u);
  EXPECT_EQ(result.stats.events_in, expected.size());
  const auto req = cam.vendor_requests();
  ASSERT_EQ(req.size(), 4u);  // biases, reset, start ... stop
  EXPECT_EQ(req[0], 0xB8);
  EXPECT_EQ(req[1], 0xBB);
  EXPECT_EQ(req[2], 0xB3);
  EXPECT_EQ(req[3], 0xB4);
}

// Words for `n` ON events with 1 us spacing and wrap words where due.
std::vector<std::uint32_t> event_stream(int n, int& t_us, std::vector<Event>* truth) {
  std::vector<std::uint32_t> words;
  for (int i = 0; i < n; ++i) {
    ++t_us;
    if (t_us % 0x4000 == 0) words.push_back(kWrapWord);
    const int raw_x = i % 128;
    const int raw_y = (i / 128) % 128;
    words.push_back(dvs128_word(raw_x, raw_y, false, t_us % 0x4000));
    if (truth != nullptr) {
      truth->push_back({t_us, static_cast<std::uint16_t>(127 - raw_x),
                        static_cast<std::uint16_t>(127 - raw_y), 1});
    }
  }
  return words;
}

TEST(Dvs128Source, BurstLargerThanTheQueuesDropsAndCountsAndLosesNothingElse) {
  UsbTestbed bed;
  auto& cam = bed.add_dvs128();
  int t_us = 0;
  std::vector<Event> truth;
  const int packets = 60;
  const int per_packet = 1000;  // 4000 bytes: one transfer each
  for (int p = 0; p < packets; ++p) cam.push_packet(words_to_bytes(event_stream(per_packet, t_us, &truth)));

  auto source = evlife::engine::make_dvs128_source("dvs128");
  Collector out;
  out.delay_per_write = 2ms;  // a slow consumer
  EngineOptions options = quiet_options();
  options.batch_events = 16;
  options.batches_per_worker = 2;  // queues far smaller than the burst
  Engine engine(*source, &out.sink, options);
  RunResult result;
  std::thread runner([&] { result = engine.run(); });
  const bool read_all = wait_until([&] { return engine.stats().events_in >= truth.size(); });
  engine.request_stop();
  runner.join();
  ASSERT_TRUE(read_all) << engine.stats().events_in;

  const auto& s = result.stats;
  EXPECT_EQ(s.events_in, truth.size());  // the source read every event the camera sent
  EXPECT_EQ(s.events_in, s.events_out + s.events_dropped);
  EXPECT_GT(s.events_dropped, 0u) << "the burst should overflow the queues";
  EXPECT_EQ(out.events.size(), s.events_out);
  // What came out is the input minus drops: a subsequence, in order, unchanged.
  std::size_t j = 0;
  for (const auto& a : out.events) {
    while (j < truth.size() && (truth[j].t_us != a.event.t_us || truth[j].x != a.event.x ||
                                truth[j].y != a.event.y)) {
      ++j;
    }
    ASSERT_LT(j, truth.size()) << "an output event that was never sent";
    ++j;
  }
}

TEST(Dvs128Source, UnplugMidStreamEndsCleanlyWithEverythingReadAndAnError) {
  UsbTestbed bed;
  auto& cam = bed.add_dvs128();
  int t_us = 0;
  std::vector<Event> truth;
  for (int p = 0; p < 5; ++p) cam.push_packet(words_to_bytes(event_stream(700, t_us, &truth)));

  auto source = evlife::engine::make_dvs128_source("dvs128");
  Collector out;
  Engine engine(*source, &out.sink, quiet_options());
  RunResult result;
  std::thread runner([&] { result = engine.run(); });
  // Mid-stream: once the camera has handed its data to the host, it vanishes.
  EXPECT_TRUE(cam.wait_for([&] { return cam.queued_packets() == 0; }));
  cam.unplug();
  const bool ended = wait_until([&] { return source->status() != evlife::engine::SourceStatus::ok; });
  if (!ended) engine.request_stop();
  runner.join();
  ASSERT_TRUE(ended);

  EXPECT_EQ(result.status, RunStatus::source_error);
  EXPECT_NE(result.exit_code(), 0);
  EXPECT_NE(result.message.find("vanished"), std::string::npos) << result.message;
  EXPECT_EQ(result.stats.events_dropped, 0u);
  ASSERT_EQ(out.events.size(), truth.size());  // nothing that was read is lost
  for (std::size_t i = 0; i < truth.size(); ++i) {
    ASSERT_EQ(out.events[i].event.t_us, truth[i].t_us) << i;
  }
  const auto req = cam.vendor_requests();
  EXPECT_EQ(std::count(req.begin(), req.end(), 0xB4), 0);  // no STOP to a vanished device
}

// A transfer that fails (EPROTO) loses its events without saying how many
// (it reports no data): the summary shows the failed transfer beside the
// balance (before: "lost in source 0" and "balance: ... ok", nothing else).
TEST(Dvs128Source, AFailedTransferIsShownNotSilentlyLost) {
  UsbTestbed bed;
  auto& cam = bed.add_dvs128();
  int t_us = 0;
  std::vector<Event> kept;
  std::vector<Event> lost;
  cam.fail_next_packet(EPROTO);
  cam.push_packet(words_to_bytes(event_stream(100, t_us, &lost)));
  cam.push_packet(words_to_bytes(event_stream(100, t_us, &kept)));

  auto source = evlife::engine::make_dvs128_source("dvs128");
  Collector out;
  Engine engine(*source, &out.sink, quiet_options());
  RunResult result;
  std::thread runner([&] { result = engine.run(); });
  EXPECT_TRUE(wait_until([&] { return out.count.load() >= kept.size(); }));
  engine.request_stop();
  runner.join();

  EXPECT_EQ(out.events.size(), kept.size());
  EXPECT_EQ(result.stats.source_failed_transfers, 1u);
  const std::string summary = result.stats.summary();
  EXPECT_NE(summary.find("(and 1 failed device transfers: their events are lost, not all counted)"), std::string::npos)
      << summary;
  EXPECT_NE(summary.find("; lost before the engine: 0 events and 1 failed device transfers"), std::string::npos)
      << summary;
}

TEST(Dvs128Source, NoCameraIsAClearError) {
  UsbTestbed bed;
  bed.add_other_device(0x1d6b, 0x0002, 1, 1);
  try {
    auto source = evlife::engine::make_dvs128_source("dvs128");
    FAIL() << "a camera was opened";
  } catch (const std::exception& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("no DVS128"), std::string::npos) << m;
    EXPECT_NE(m.find("1d6b:0002"), std::string::npos) << m;
    EXPECT_NE(m.find("udev"), std::string::npos) << m;
  }
}

TEST(Dvs128Source, SpecSelectsTheSerialAndBiasFileOverridesDefaults) {
  UsbTestbed bed;
  auto& a = bed.add_dvs128("AAA", 14, 1, 2);
  auto& b = bed.add_dvs128("BBB", 14, 1, 3);
  const std::string path = (std::filesystem::path(EVLIFE_BINARY_DIR) / "test_dvs128_biases.yaml").string();
  {
    std::ofstream f(path);
    f << "# test biases\ndvs128_biases:\n  cas: 5   # changed\n  PR: 0x10\n";
  }
  // "0x10" is not a decimal integer: the error names the file and line.
  try {
    evlife::engine::make_dvs128_source("dvs128:BBB", path);
    FAIL() << "accepted a bad bias value";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path + ":4:"), std::string::npos) << e.what();
  }
  {
    std::ofstream f(path);
    f << "# test biases\ndvs128_biases:\n  cas: 5   # changed\n  PR: 16\n";
  }
  auto source = evlife::engine::make_dvs128_source("dvs128:BBB", path);
  EXPECT_NE(source->describe().find("BBB"), std::string::npos);
  EXPECT_TRUE(a.vendor_requests().empty());
  const auto controls = b.control_requests();
  const auto it = std::find_if(controls.begin(), controls.end(),
                               [](const auto& c) { return c.request == 0xB8; });
  ASSERT_NE(it, controls.end());
  ASSERT_EQ(it->data.size(), 36u);
  EXPECT_EQ(it->data[0], 0x00);
  EXPECT_EQ(it->data[1], 0x00);
  EXPECT_EQ(it->data[2], 0x05);  // cas = 5
  EXPECT_EQ(it->data[3], 0x10);  // injGnd default 1108364 = 0x10E98C
  EXPECT_EQ(it->data[35], 0x10);  // pr = 16
  std::remove(path.c_str());
}

}  // namespace
