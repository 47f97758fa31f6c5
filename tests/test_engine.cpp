// The engine: routing, determinism, equality with the single-threaded
// estimator, overload accounting, shutdown, errors. Expected values come from
// the bare LifetimeEstimator run by hand (not from the engine) or from
// counting; stages are also driven without threads (Pipeline::step_all).
#include <gtest/gtest.h>
#include <grp.h>
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "evlife/algo/lifetime_estimator.h"
#include "evlife/engine/engine.h"
#include "evlife/engine/event_clock_pacer.h"
#include "evlife/engine/realtime_thread.h"
#include "evlife/engine/packet_source.h"
#include "evlife/engine/pipeline.h"
#include "evlife/engine/pipeline_state.h"
#include "evlife/engine/replay_source.h"
#include "evlife/engine/tile_layout.h"
#include "evlife/io/event_reader.h"
#include "evlife/io/synthetic_scene.h"
#include "evlife/io/write_error.h"
#include "sanitizer_build.h"

namespace ee = evlife::engine;
using evlife::AugmentedEvent;
using evlife::Event;
using evlife::SensorSize;

namespace {

// Bit-exact comparison (NaN prediction errors compare equal as bits).
bool same_bits(const std::vector<AugmentedEvent>& a, const std::vector<AugmentedEvent>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(AugmentedEvent)) == 0);
}

bool same_bits(const AugmentedEvent& a, const AugmentedEvent& b) {
  return std::memcmp(&a, &b, sizeof(AugmentedEvent)) == 0;
}

std::vector<Event> read_all(const std::string& path, std::size_t max_events) {
  auto reader = evlife::io::open_event_reader(path);
  std::vector<Event> events(max_events);
  std::size_t n = 0;
  while (n < max_events) {
    const std::size_t got = reader->read(std::span<Event>(events.data() + n, max_events - n));
    if (got == 0) break;
    n += got;
  }
  events.resize(n);
  return events;
}

// A recording that exercises real motion: the first n events of stripes.mat.
std::vector<Event> stripes(std::size_t n = 60'000) {
  static const std::vector<Event> events =
      read_all(std::string(EVLIFE_SHARED_DATA_DIR) + "/reference/stripes.mat", 60'000);
  return std::vector<Event>(events.begin(),
                            events.begin() + static_cast<std::ptrdiff_t>(std::min(n, events.size())));
}
const SensorSize kDvs128{128, 128};

evlife::LifetimeOptions lifetime_options(SensorSize sensor) {
  evlife::LifetimeOptions o;
  o.sensor = sensor;
  return o;
}

std::vector<AugmentedEvent> bare_estimator(const std::vector<Event>& events, SensorSize sensor) {
  evlife::LifetimeEstimator est(lifetime_options(sensor));
  std::vector<AugmentedEvent> out(events.size());
  est.process(events, out);
  return out;
}

struct Collector {
  std::vector<AugmentedEvent> events;
  ee::CallbackSink sink{[this](std::span<const AugmentedEvent> s) {
    events.insert(events.end(), s.begin(), s.end());
  }};
};

ee::EngineOptions engine_options(int workers, int tiles_x, int tiles_y, SensorSize sensor) {
  ee::EngineOptions o;
  o.lifetime = lifetime_options(sensor);
  o.workers = workers;
  o.tiles_x = tiles_x;
  o.tiles_y = tiles_y;
  o.batch_events = 256;
  o.batches_per_worker = 8;
  o.stats_period_s = 0.0;
  return o;
}

// Two workers (one per polarity), pools of two 64-event batches and a fixed
// policy: small enough that the stepped tests reach blocking and dropping.
ee::EngineOptions tight_options(ee::OverloadPolicy policy) {
  auto options = engine_options(2, 1, 1, kDvs128);
  options.batch_events = 64;
  options.batches_per_worker = 2;
  options.auto_policy = false;
  options.policy = policy;
  return options;
}

std::vector<AugmentedEvent> run_threaded(const std::vector<Event>& events, SensorSize sensor,
                                         const ee::EngineOptions& options,
                                         ee::RunResult* result_out = nullptr) {
  ee::ReplaySource source(events, sensor);
  Collector out;
  ee::Engine engine(source, &out.sink, options);
  const ee::RunResult result = engine.run();
  EXPECT_EQ(result.status, ee::RunStatus::completed) << result.message;
  EXPECT_EQ(result.stats.events_in, events.size());
  EXPECT_EQ(result.stats.events_out, events.size());
  if (result_out != nullptr) *result_out = result;
  return out.events;
}

std::vector<AugmentedEvent> run_inline(const std::vector<Event>& events, SensorSize sensor,
                                       const ee::EngineOptions& options) {
  ee::ReplaySource source(events, sensor);
  Collector out;
  ee::Pipeline pipeline(source, &out.sink, options);
  pipeline.run_inline();
  return out.events;
}

// A source that hands out `good` events, then fails like a vanished device.
class FailingSource final : public ee::EventSource {
 public:
  FailingSource(std::vector<Event> events, std::size_t chunk) : events_(std::move(events)), chunk_(chunk) {}
  std::size_t pull(std::span<Event> out) noexcept override {
    if (status_ != ee::SourceStatus::ok) return 0;
    if (pos_ == events_.size()) {
      status_ = ee::SourceStatus::error;
      return 0;
    }
    const std::size_t n = std::min({out.size(), chunk_, events_.size() - pos_});
    std::copy_n(events_.begin() + static_cast<std::ptrdiff_t>(pos_), n, out.begin());
    pos_ += n;
    return n;
  }
  ee::SourceStatus status() const noexcept override { return status_; }
  std::string error_message() const override { return "usb:test device vanished (LIBUSB_ERROR_NO_DEVICE)"; }
  SensorSize sensor_size() const noexcept override { return kDvs128; }
  ee::SourceKind kind() const noexcept override { return ee::SourceKind::live; }
  std::string describe() const override { return "failing test source"; }
  void request_stop() noexcept override {}

 private:
  std::vector<Event> events_;
  std::size_t chunk_;
  std::size_t pos_ = 0;
  ee::SourceStatus status_ = ee::SourceStatus::ok;
};

}  // namespace

// ---- Routing ----------------------------------------------------------------

TEST(TileLayout, WholePolaritiesGoToDifferentWorkers) {
  const ee::TileLayout layout(kDvs128, 2, 1, 1, 0);
  for (int y = 0; y < 128; y += 7) {
    for (int x = 0; x < 128; x += 5) {
      const Event on{0, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), 1};
      const Event off{0, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), -1};
      EXPECT_EQ(layout.owner(on), 0);
      EXPECT_EQ(layout.owner(off), 1);
      EXPECT_EQ(layout.feed_mask(on), 1u);
      EXPECT_EQ(layout.feed_mask(off), 2u);
    }
  }
  EXPECT_EQ(layout.owner(Event{0, 128, 0, 1}), ee::TileLayout::kNoOwner);
  EXPECT_EQ(layout.owner(Event{0, 0, 0, 0}), ee::TileLayout::kNoOwner);
  EXPECT_TRUE(layout.owner_only());
  EXPECT_TRUE(ee::TileLayout(kDvs128, 2, 1, 1, 20).owner_only());  // one tile: no one else to feed
  EXPECT_TRUE(ee::TileLayout(kDvs128, 4, 2, 2, 0).owner_only());
  EXPECT_FALSE(ee::TileLayout(kDvs128, 4, 2, 2, 1).owner_only());
}

TEST(Pipeline, OwnerOnlyRoutingKeepsOffSensorEventsInPlace) {
  // Owner-only routing (1x1 tiles): an off-sensor event and one of polarity
  // 0 go to worker 0, are counted and come out in their input positions.
  std::vector<Event> events;
  for (int i = 0; i < 300; ++i)
    events.push_back(Event{i, static_cast<std::uint16_t>(i % 128), 7, static_cast<std::int8_t>(i % 3 ? 1 : -1)});
  events[100].x = 500;
  events[201].p = 0;
  const auto out = run_inline(events, kDvs128, engine_options(2, 1, 1, kDvs128));
  ASSERT_EQ(out.size(), events.size());
  for (std::size_t i = 0; i < events.size(); ++i) {
    ASSERT_EQ(out[i].event.t_us, events[i].t_us) << i;
    ASSERT_EQ(out[i].event.x, events[i].x) << i;
    ASSERT_EQ(out[i].event.p, events[i].p) << i;
  }
}

// The events a worker's estimator rejects (labelled noise unexamined) are in
// the engine's stats, each once, by its owner: an embedding host sees them
// without reaching into the workers. A margin worker fed the same event
// rejects it too (a time going backwards in its stream): not counted.
TEST(Pipeline, RejectedEventsAreCountedOnceByTheirOwner) {
  std::vector<Event> events;
  for (int i = 0; i < 3'000; ++i)
    events.push_back(Event{1'000 + 37 * i, static_cast<std::uint16_t>((i * 7) % 128),
                           static_cast<std::uint16_t>((i * 5) % 128), static_cast<std::int8_t>(i % 3 ? 1 : -1)});
  events[100].x = 500;                       // outside the sensor
  events[201].p = 0;                         // no polarity
  events[1'501] = Event{1'000, 63, 64, 1};   // back to the first time, at the corner of 4 tiles
  evlife::LifetimeEstimator bare(lifetime_options(kDvs128));
  for (const Event& e : events) bare.process(e);
  ASSERT_EQ(bare.stats().rejected(), 3u);
  for (const auto& [tiles, margin] : {std::pair{1, 0}, std::pair{2, 4}}) {
    auto options = engine_options(2, tiles, tiles, kDvs128);
    options.margin_px = margin;
    ee::ReplaySource source(events, kDvs128);
    Collector out;
    ee::Pipeline pipeline(source, &out.sink, options);
    pipeline.run_inline();
    const ee::EngineStats stats = pipeline.stats();
    EXPECT_EQ(stats.rejected(), 3u) << tiles << " tiles";
    std::uint64_t fed_rejections = 0;  // what the workers' estimators counted, margin events included
    for (int w = 0; w < pipeline.worker_count(); ++w) fed_rejections += pipeline.worker(w).estimator().stats().rejected();
    if (tiles > 1) {
      EXPECT_GT(fed_rejections, 3u) << "the margin workers were fed the step back too";
    }
    EXPECT_NE(stats.summary().find(" (labelled noise unexamined)"), std::string::npos) << stats.summary();
    ASSERT_EQ(out.events.size(), events.size());
    EXPECT_TRUE(out.events[1'501].is_noise());
  }
}

TEST(TileLayout, FeedMaskIsOwnTilesGrownByTheMargin) {
  // 3x2 tiles per polarity over 100x60, 4 workers, margin 6: checked against
  // a direct computation of the Chebyshev distance to every tile.
  const SensorSize sensor{100, 60};
  const int margin = 6;
  const ee::TileLayout layout(sensor, 4, 3, 2, margin);
  EXPECT_FALSE(layout.owner_only());
  for (int p : {1, -1}) {
    const int pi = p > 0 ? 0 : 1;
    for (int y = 0; y < sensor.height; ++y) {
      for (int x = 0; x < sensor.width; ++x) {
        std::uint32_t expect_mask = 0;
        int expect_owner = -1;
        for (int row = 0; row < 2; ++row) {
          for (int col = 0; col < 3; ++col) {
            const int x0 = col * 100 / 3, x1 = (col + 1) * 100 / 3;
            const int y0 = row * 60 / 2, y1 = (row + 1) * 60 / 2;
            const int w = ((pi * 2 + row) * 3 + col) % 4;
            if (x >= x0 && x < x1 && y >= y0 && y < y1) expect_owner = w;
            const int dx = x < x0 ? x0 - x : (x >= x1 ? x - x1 + 1 : 0);
            const int dy = y < y0 ? y0 - y : (y >= y1 ? y - y1 + 1 : 0);
            if (std::max(dx, dy) <= margin) expect_mask |= 1u << w;
          }
        }
        const Event e{0, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y),
                      static_cast<std::int8_t>(p)};
        ASSERT_EQ(layout.owner(e), expect_owner) << x << "," << y;
        ASSERT_EQ(layout.feed_mask(e), expect_mask) << x << "," << y;
      }
    }
  }
}

// ---- Equality with the single-threaded estimator ---------------------------

TEST(Pipeline, InlineOneTilePerPolarityEqualsBareEstimator) {
  const auto& events = stripes();
  ASSERT_GT(events.size(), 10'000u);
  const auto expect = bare_estimator(events, kDvs128);
  const auto got = run_inline(events, kDvs128, engine_options(2, 1, 1, kDvs128));
  ASSERT_EQ(got.size(), expect.size());
  for (std::size_t i = 0; i < got.size(); ++i)
    ASSERT_TRUE(same_bits(got[i], expect[i])) << "event " << i;
}

TEST(Engine, ThreadedOneTilePerPolarityEqualsBareEstimator) {
  const auto& events = stripes(20'000);
  const auto expect = bare_estimator(events, kDvs128);
  for (int workers : {1, 2}) {
    const auto got = run_threaded(events, kDvs128, engine_options(workers, 1, 1, kDvs128));
    ASSERT_EQ(got.size(), expect.size());
    for (std::size_t i = 0; i < got.size(); ++i)
      ASSERT_TRUE(same_bits(got[i], expect[i])) << workers << " workers, event " << i;
  }
}

TEST(Engine, OutputKeepsInputOrderWithTiles) {
  const auto& events = stripes(20'000);
  auto options = engine_options(3, 2, 2, kDvs128);
  options.margin_px = 4;
  const auto got = run_threaded(events, kDvs128, options);
  ASSERT_EQ(got.size(), events.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    ASSERT_EQ(got[i].event.t_us, events[i].t_us) << i;
    ASSERT_EQ(got[i].event.x, events[i].x) << i;
    ASSERT_EQ(got[i].event.y, events[i].y) << i;
    ASSERT_EQ(got[i].event.p, events[i].p) << i;
  }
}

// ---- Determinism -------------------------------------------------------------

TEST(Engine, TiledRunsAreBitIdenticalAcrossRunsAndToInlineSteps) {
  const auto& events = stripes(20'000);
  auto options = engine_options(3, 2, 2, kDvs128);
  options.margin_px = 3;  // small margin: tiles do differ from the bare estimator
  const auto inline_out = run_inline(events, kDvs128, options);
  for (int run = 0; run < 3; ++run) {
    const auto got = run_threaded(events, kDvs128, options);
    ASSERT_TRUE(same_bits(got, inline_out)) << "run " << run;
  }
}

TEST(Engine, WideMarginTilesMatchBareEstimatorOnMostEvents) {
  // Not a determinism test: documents that a wide margin approaches the
  // single-threaded result (the README quotes the measured shares).
  const auto& events = stripes();
  const auto expect = bare_estimator(events, kDvs128);
  auto options = engine_options(2, 2, 2, kDvs128);
  options.margin_px = 20;
  const auto got = run_inline(events, kDvs128, options);
  ASSERT_EQ(got.size(), expect.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < got.size(); ++i)
    differ += got[i].lifetime_us != expect[i].lifetime_us ? 1 : 0;
  EXPECT_LT(static_cast<double>(differ), 0.05 * static_cast<double>(got.size()));
}

// ---- Steps without threads --------------------------------------------------

TEST(Pipeline, RouterBlocksWhenAWorkersPoolIsFullThenResumes) {
  std::vector<Event> events;
  for (int i = 0; i < 64 * 10; ++i)
    events.push_back(Event{i, static_cast<std::uint16_t>(i % 128), 5, 1});  // all ON -> worker 0
  ee::ReplaySource source(events, kDvs128);
  const auto options = tight_options(ee::OverloadPolicy::block);
  Collector out;
  ee::Pipeline pipeline(source, &out.sink, options);
  EXPECT_EQ(pipeline.router().step(), ee::StepResult::progressed);
  EXPECT_EQ(pipeline.router().step(), ee::StepResult::progressed);
  EXPECT_EQ(pipeline.router().step(), ee::StepResult::blocked);  // worker 0's 2 batches in use
  EXPECT_EQ(pipeline.router().step(), ee::StepResult::blocked);
  EXPECT_EQ(pipeline.worker(1).step(), ee::StepResult::idle);
  EXPECT_EQ(pipeline.worker(0).step(), ee::StepResult::progressed);
  EXPECT_EQ(pipeline.router().step(), ee::StepResult::blocked);  // output not merged yet
  EXPECT_EQ(pipeline.merger().step(), ee::StepResult::progressed);
  EXPECT_EQ(pipeline.router().step(), ee::StepResult::progressed);
  pipeline.run_inline();
  const auto st = pipeline.stats();
  EXPECT_EQ(st.events_in, events.size());
  EXPECT_EQ(st.events_out, events.size());
  EXPECT_EQ(st.events_dropped, 0u);
  EXPECT_EQ(out.events.size(), events.size());
  EXPECT_EQ(st.workers[0].in_flight_hwm, 2u);
  EXPECT_EQ(pipeline.merger().step(), ee::StepResult::finished);
}

TEST(PipelineState, BlockedRouterIsWokenOnceHalfThePoolItWaitsOnIsFree) {
  auto options = tight_options(ee::OverloadPolicy::block);
  options.batches_per_worker = 8;
  ee::PipelineState block(options, kDvs128, ee::OverloadPolicy::block);
  const std::uint64_t worker1 = 2;
  block.room_returned(worker1, 8, 8);  // the router waits on nothing
  EXPECT_EQ(block.wake_router.availableApprox(), 0);
  block.router_waiting.store(worker1);
  block.room_returned(1, 8, 8);  // worker 0's pool: not the one it waits on
  block.room_returned(ee::PipelineState::kOrderPoolBit, 16, 16);
  block.room_returned(worker1, 3, 8);
  EXPECT_EQ(block.wake_router.availableApprox(), 0);
  block.room_returned(worker1, 4, 8);
  EXPECT_EQ(block.wake_router.availableApprox(), 1);
  block.room_returned(worker1, 8, 8);
  EXPECT_EQ(block.wake_router.availableApprox(), 1);  // wake-ups do not pile up
  ee::PipelineState drop(options, kDvs128, ee::OverloadPolicy::drop);
  drop.room_returned(worker1, 1, 8);
  EXPECT_EQ(drop.wake_router.availableApprox(), 1);
}

TEST(Pipeline, BlockedRouterMarksThePoolsItWaitsOn) {
  std::vector<Event> events;
  for (int i = 0; i < 64 * 10; ++i)
    events.push_back(Event{i, static_cast<std::uint16_t>(i % 128), 5, 1});  // all ON -> worker 0
  ee::ReplaySource source(events, kDvs128);
  Collector out;
  ee::Pipeline pipeline(source, &out.sink, tight_options(ee::OverloadPolicy::block));
  EXPECT_EQ(pipeline.router().step(), ee::StepResult::progressed);
  EXPECT_EQ(pipeline.state().router_waiting.load(), 0u);
  EXPECT_EQ(pipeline.router().step(), ee::StepResult::progressed);
  EXPECT_EQ(pipeline.router().step(), ee::StepResult::blocked);  // worker 0's 2 batches in use
  EXPECT_EQ(pipeline.state().router_waiting.load(), 1u);
  pipeline.run_inline();
  EXPECT_EQ(out.events.size(), events.size());
}

TEST(Pipeline, DropPolicyCountsEveryDroppedEvent) {
  std::vector<Event> events;
  for (int i = 0; i < 64 * 10; ++i)
    events.push_back(Event{i, static_cast<std::uint16_t>(i % 128), 5,
                           static_cast<std::int8_t>(i % 3 == 0 ? -1 : 1)});
  ee::ReplaySource source(events, kDvs128);
  const auto options = tight_options(ee::OverloadPolicy::drop);
  Collector out;
  ee::Pipeline pipeline(source, &out.sink, options);
  for (int i = 0; i < 10; ++i) pipeline.router().step();  // workers never run: pools fill
  pipeline.run_inline();
  const auto st = pipeline.stats();
  EXPECT_EQ(st.events_in, events.size());
  EXPECT_GT(st.events_dropped, 0u);
  EXPECT_EQ(st.events_in, st.events_out + st.events_dropped);
  EXPECT_EQ(out.events.size(), st.events_out);
  // The survivors are the first two chunks of each polarity (pool size 2), in order.
  EXPECT_EQ(st.events_out, 2u * 64u);
  for (std::size_t i = 0; i < out.events.size(); ++i)
    ASSERT_EQ(out.events[i].event.t_us, events[i].t_us);
}

// ---- Overload with threads --------------------------------------------------

TEST(Engine, SlowSinkWithDropPolicyBalancesInOutDropped) {
  // Offline and live: live, the source thread runs worker 1 itself and
  // must still read everything, the slow sink showing as counted drops.
  for (const ee::SourceKind kind : {ee::SourceKind::offline, ee::SourceKind::live}) {
    SCOPED_TRACE(kind == ee::SourceKind::live ? "live" : "offline");
    const auto& events = stripes(20'000);
    ee::ReplaySource source(events, kDvs128, 0.0, kind);
    const auto options = tight_options(ee::OverloadPolicy::drop);
    std::size_t received = 0;
    std::int64_t last_t = -1;
    bool ordered = true;
    ee::CallbackSink slow([&](std::span<const AugmentedEvent> s) {
      std::this_thread::sleep_for(std::chrono::microseconds(300));  // a disk that cannot keep up
      for (const auto& a : s) {
        ordered = ordered && a.event.t_us >= last_t;
        last_t = a.event.t_us;
      }
      received += s.size();
    });
    ee::Engine engine(source, &slow, options);
    const ee::RunResult r = engine.run();
    EXPECT_EQ(r.status, ee::RunStatus::completed);
    EXPECT_EQ(r.stats.events_in, events.size());
    EXPECT_GT(r.stats.events_dropped, 0u) << "the sink was not slow enough to overload";
    EXPECT_EQ(r.stats.events_in, r.stats.events_out + r.stats.events_dropped);
    EXPECT_EQ(received, r.stats.events_out);
    std::uint64_t per_worker = r.stats.dropped_no_order;
    for (const auto& w : r.stats.workers) per_worker += w.dropped;
    EXPECT_EQ(per_worker, r.stats.events_dropped);
    EXPECT_TRUE(ordered);
    if (kind == ee::SourceKind::live) {
      EXPECT_EQ(r.thread_cpu_s.front().first, "source+worker1");
      EXPECT_GT(r.stats.workers[1].dropped, 0u) << "the hosted worker's pool ran out too";
    }
  }
}

TEST(Engine, SlowSinkWithBlockPolicyLosesNothing) {
  const auto& events = stripes(5'000);
  ee::ReplaySource source(events, kDvs128);
  const auto options = tight_options(ee::OverloadPolicy::block);
  Collector out;
  ee::CallbackSink slow([&](std::span<const AugmentedEvent> s) {
    std::this_thread::sleep_for(std::chrono::microseconds(200));
    out.events.insert(out.events.end(), s.begin(), s.end());
  });
  ee::Engine engine(source, &slow, options);
  const ee::RunResult r = engine.run();
  EXPECT_EQ(r.stats.events_dropped, 0u);
  EXPECT_GT(r.stats.source_blocked_s, 0.0);
  EXPECT_TRUE(same_bits(out.events, bare_estimator(events, kDvs128)));
}

// ---- Shutdown and errors ----------------------------------------------------

TEST(Engine, StopMidStreamProcessesEverythingAccepted) {
  const auto& events = stripes(60'000);  // 0.2 s of recording replayed at 0.5x: ~0.4 s
  ee::ReplaySource source(events, kDvs128, 0.5);
  Collector out;
  ee::Engine engine(source, &out.sink, engine_options(2, 1, 1, kDvs128));
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    engine.request_stop();
  });
  const ee::RunResult r = engine.run();
  stopper.join();
  EXPECT_EQ(r.status, ee::RunStatus::interrupted);
  EXPECT_EQ(r.exit_code(), 130);
  EXPECT_GT(r.stats.events_in, 0u);
  EXPECT_LT(r.stats.events_in, events.size()) << "stopped too late to test anything";
  EXPECT_EQ(r.stats.events_dropped, 0u);
  EXPECT_EQ(r.stats.events_out, r.stats.events_in);
  // What was accepted is a prefix of the input, processed exactly as the bare estimator would.
  const std::vector<Event> prefix(events.begin(), events.begin() + static_cast<std::ptrdiff_t>(r.stats.events_in));
  EXPECT_TRUE(same_bits(out.events, bare_estimator(prefix, kDvs128)));
}

TEST(Engine, VanishedDeviceEndsRunWithErrorAfterFlushingItsEvents) {
  const auto& events = stripes(3'000);
  FailingSource source(events, 100);
  Collector out;
  auto options = engine_options(2, 1, 1, kDvs128);
  options.auto_policy = false;  // a live source defaults to drop; here nothing may be lost
  options.policy = ee::OverloadPolicy::block;
  ee::Engine engine(source, &out.sink, options);
  const ee::RunResult r = engine.run();
  EXPECT_EQ(r.status, ee::RunStatus::source_error);
  EXPECT_EQ(r.exit_code(), evlife::kExitInput);  // the CLI's scheme: 3, as `evlife run` exits
  EXPECT_NE(r.message.find("vanished"), std::string::npos);
  EXPECT_EQ(out.events.size(), events.size());
  EXPECT_EQ(r.stats.events_dropped, 0u);
}

TEST(Engine, FailingSinkEndsRunWithErrorAndKeepsAccounting) {
  const auto& events = stripes(5'000);
  ee::ReplaySource source(events, kDvs128);
  std::size_t calls = 0;
  ee::CallbackSink failing([&](std::span<const AugmentedEvent>) {
    if (++calls == 3) throw std::runtime_error("out.bin: write failed: No space left on device");
  });
  ee::Engine engine(source, &failing, engine_options(2, 1, 1, kDvs128));
  const ee::RunResult r = engine.run();
  EXPECT_EQ(r.status, ee::RunStatus::sink_error);
  EXPECT_NE(r.message.find("No space left"), std::string::npos);
  EXPECT_EQ(calls, 3u);  // not called again after failing
  EXPECT_GT(r.stats.sink_failed, 0u);
  EXPECT_EQ(r.stats.events_in, r.stats.events_out + r.stats.events_dropped);
  // The summary must not call the run balanced without saying the output lost events.
  EXPECT_NE(r.stats.summary().find("but " + std::to_string(r.stats.sink_failed) + " of the out were not written"),
            std::string::npos)
      << r.stats.summary();
}

// A writer whose buffer the disk refused says how many records its file kept
// (io::WriteError::records_in_file): the events handed to it beyond them are
// counted not written, also those of chunks accepted before the error (the
// count said 31,750 written of a /dev/full file holding none: a review's
// finding). Finishing (the last flush) counts them too.
TEST(Engine, AFailedOutputCountsWhatItsFileLacksNotWhatWasHandedAfter) {
  const auto& events = stripes(5'000);
  for (const bool at_finish : {false, true}) {
    SCOPED_TRACE(at_finish ? "the last flush fails" : "a write fails");
    ee::ReplaySource source(events, kDvs128);
    std::size_t calls = 0, handed = 0;
    static constexpr std::uint64_t kKept = 100;  // the file's whole records
    const auto fail = [] {
      throw evlife::io::WriteError("out.bin", "write failed: No space left on device (the file ends after its last "
                                              "whole record: 100 records in it)", ENOSPC, kKept);
    };
    struct FullDiskSink final : ee::AugmentedSink {
      std::function<void(std::span<const AugmentedEvent>)> on_write;
      std::function<void()> on_finish;
      void write(std::span<const AugmentedEvent> chunk) override { on_write(chunk); }
      void finish() override { on_finish(); }
    } sink;
    sink.on_write = [&](std::span<const AugmentedEvent> chunk) {
      if (!at_finish && ++calls == 3) fail();
      handed += chunk.size();
    };
    sink.on_finish = [&] {
      if (at_finish) fail();
    };
    ee::Engine engine(source, &sink, engine_options(2, 1, 1, kDvs128));
    const ee::RunResult r = engine.run();
    EXPECT_EQ(r.status, ee::RunStatus::sink_error);
    ASSERT_GT(handed, kKept);
    if (at_finish) {
      EXPECT_EQ(r.stats.sink_failed, handed - kKept);
    } else {
      // Handed before the failing chunk, plus that chunk and every one after: all but the 100 kept.
      EXPECT_EQ(r.stats.sink_failed, r.stats.events_out - kKept);
    }
    EXPECT_EQ(r.stats.events_in, r.stats.events_out + r.stats.events_dropped);
  }
}

TEST(Engine, FileSourceReportsMissingFileAndBadOptions) {
  EXPECT_THROW(ee::ReplaySource::open_file("/nonexistent/x.mat", std::nullopt), std::exception);
  const auto& events = stripes(100);
  ee::ReplaySource source(events, kDvs128);
  auto options = engine_options(0, 1, 1, kDvs128);
  try {
    ee::Engine engine(source, nullptr, options);
    FAIL() << "0 workers accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("workers"), std::string::npos);
  }
}

TEST(Engine, NoSinkStillCountsAndMeasuresLatency) {
  const auto& events = stripes(10'000);
  ee::ReplaySource source(events, kDvs128);
  ee::Engine engine(source, nullptr, engine_options(2, 1, 1, kDvs128));
  const ee::RunResult r = engine.run();
  EXPECT_EQ(r.stats.events_out, events.size());
  EXPECT_EQ(r.stats.latency_count, events.size());
  EXPECT_GT(r.stats.latency_max_us, 0.0);
  EXPECT_LE(r.stats.latency_p50_us, r.stats.latency_p99_us);
  EXPECT_LE(r.stats.latency_p99_us, r.stats.latency_max_us);
}

TEST(Engine, ReportsTheCpuTimeOfEachThread) {
  const auto& events = stripes(10'000);
  ee::ReplaySource source(events, kDvs128);
  ee::Engine engine(source, nullptr, engine_options(2, 1, 1, kDvs128));
  const ee::RunResult r = engine.run();
  std::vector<std::string> names;
  for (const auto& [name, cpu_s] : r.thread_cpu_s) {
    names.push_back(name);
    EXPECT_GE(cpu_s, 0.0) << name;
  }
  EXPECT_EQ(names, (std::vector<std::string>{"source", "worker0", "worker1", "merger"}));
  EXPECT_GT(r.thread_cpu_s[1].second, 0.0);  // the workers estimated 10,000 events
  EXPECT_GT(r.thread_cpu_s[2].second, 0.0);
}

TEST(Engine, LiveRunsHaveTheSourceThreadRunTheLastWorker) {
  // Live (policy drop, live source), 2+ workers: the source thread steps
  // the last worker itself; no thread of its own. Same bits as the bare
  // estimator.
  const auto& events = stripes(10'000);
  const auto expect = bare_estimator(events, kDvs128);
  for (const int workers : {1, 2}) {
    ee::ReplaySource source(events, kDvs128, 0.0, ee::SourceKind::live);
    auto options = engine_options(workers, 1, 1, kDvs128);
    options.batches_per_worker = 64;  // 40 chunks: room for all, nothing dropped
    Collector out;
    ee::Engine engine(source, &out.sink, options);
    const ee::RunResult r = engine.run();
    ASSERT_EQ(r.stats.events_dropped, 0u);
    std::vector<std::string> names;
    for (const auto& [name, cpu_s] : r.thread_cpu_s) names.push_back(name);
    if (workers == 1) {
      EXPECT_EQ(names, (std::vector<std::string>{"source", "worker0", "merger"}));
    } else {
      EXPECT_EQ(names, (std::vector<std::string>{"source+worker1", "worker0", "merger"}));
    }
    if (workers == 2) {
      EXPECT_GT(r.thread_cpu_s[0].second, 0.0);  // it estimated worker 1's events
    }
    ASSERT_EQ(out.events.size(), expect.size());
    for (std::size_t i = 0; i < expect.size(); ++i)
      ASSERT_TRUE(same_bits(out.events[i], expect[i])) << workers << " workers, event " << i;
  }
  EXPECT_EQ(ee::live_hosted_worker(ee::OverloadPolicy::drop, ee::SourceKind::live, 3), 2);
  EXPECT_EQ(ee::live_hosted_worker(ee::OverloadPolicy::block, ee::SourceKind::live, 3), -1);
  EXPECT_EQ(ee::live_hosted_worker(ee::OverloadPolicy::drop, ee::SourceKind::offline, 3), -1);
  EXPECT_EQ(ee::live_hosted_worker(ee::OverloadPolicy::drop, ee::SourceKind::live, 1), -1);
}

TEST(Engine, StatsGiveTheFirstAndLastEventTimeHandedOut) {
  const auto& events = stripes(10'000);
  ee::RunResult r;
  run_threaded(events, kDvs128, engine_options(2, 1, 1, kDvs128), &r);
  ASSERT_TRUE(r.stats.has_time_range);
  EXPECT_EQ(r.stats.first_t_us, events.front().t_us);
  EXPECT_EQ(r.stats.last_t_us, events.back().t_us);
  ee::ReplaySource empty(std::vector<Event>{}, kDvs128);
  ee::Engine engine(empty, nullptr, engine_options(2, 1, 1, kDvs128));
  EXPECT_FALSE(engine.run().stats.has_time_range);
}

// ---- The pipeline in a host's scheduler: run_for() and PacketSource ---------

TEST(PacketSource, RefusesAndCountsWhatDoesNotFitThenEndsAfterClose) {
  const auto events = stripes(100);
  ee::PacketSource source(kDvs128, 64);
  EXPECT_EQ(source.kind(), ee::SourceKind::live);
  EXPECT_EQ(source.push(std::span<const Event>(events.data(), 40)), 40u);
  EXPECT_EQ(source.push(std::span<const Event>(events.data() + 40, 40)), 24u);  // 16 refused
  EXPECT_EQ(source.lost_events(), 16u);
  std::vector<Event> out(100);
  EXPECT_EQ(source.pull(std::span<Event>(out.data(), 50)), 50u);
  source.close();
  EXPECT_EQ(source.status(), ee::SourceStatus::ok);  // 14 still buffered
  EXPECT_EQ(source.pull(std::span<Event>(out.data() + 50, 50)), 14u);
  EXPECT_EQ(source.status(), ee::SourceStatus::end_of_stream);
  EXPECT_EQ(source.push(std::span<const Event>(events.data(), 5)), 0u);  // after close: lost
  EXPECT_EQ(source.lost_events(), 21u);
  for (std::size_t i = 0; i < 64; ++i) ASSERT_TRUE(same_bits(AugmentedEvent{out[i]}, AugmentedEvent{events[i]}));
}

TEST(Pipeline, RunForStopsAtItsBudgetAndResumesToTheBareEstimatorsOutput) {
  const auto events = stripes(20'000);
  const auto expect = bare_estimator(events, kDvs128);
  Collector c;
  ee::PacketSource source(kDvs128, events.size());
  ee::Pipeline pipeline(source, &c.sink, engine_options(2, 1, 1, kDvs128));
  source.push(events);
  source.close();
  // Budget 0: every call makes exactly one round and says it stopped at the budget.
  int calls = 0;
  ee::PipelineRunReport r;
  do {
    r = pipeline.run_for(0);
    ++calls;
    ASSERT_EQ(r.rounds, 1);
    ASSERT_TRUE(r.finished || r.budget_exhausted);
  } while (!r.finished && calls < 1'000'000);
  ASSERT_TRUE(r.finished);
  // 256-event chunks: at least one round per chunk.
  EXPECT_GE(calls, static_cast<int>(events.size() / 256));
  EXPECT_TRUE(same_bits(c.events, expect));
  EXPECT_EQ(pipeline.run_for(1'000'000).finished, true);  // stays finished
}

TEST(Pipeline, RunForReturnsWhenTheSourceHasNothingMore) {
  const auto events = stripes(5'000);
  Collector c;
  ee::PacketSource source(kDvs128, events.size());
  ee::Pipeline pipeline(source, &c.sink, engine_options(2, 1, 1, kDvs128));
  // Nothing pushed: returns at once, idle, neither finished nor out of budget.
  ee::PipelineRunReport r = pipeline.run_for(1'000'000'000);
  EXPECT_FALSE(r.finished);
  EXPECT_FALSE(r.budget_exhausted);
  EXPECT_EQ(r.events_out, 0u);
  // Half the events: a large budget processes all of them and returns idle.
  source.push(std::span<const Event>(events.data(), 2'500));
  r = pipeline.run_for(10'000'000'000);
  EXPECT_FALSE(r.finished);
  EXPECT_FALSE(r.budget_exhausted);
  EXPECT_EQ(r.events_out, 2'500u);
  source.push(std::span<const Event>(events.data() + 2'500, 2'500));
  source.close();
  r = pipeline.run_for(10'000'000'000);
  EXPECT_TRUE(r.finished);
  EXPECT_EQ(r.events_out, 2'500u);
  EXPECT_TRUE(same_bits(c.events, bare_estimator(events, kDvs128)));
}

// A camera whose clock restarts mid-flight: without a reset every later
// event is older than the estimators' last and labelled noise (counted as
// rejected); reset_estimators() between the two clocks gives the new one's
// events what a fresh estimator gives them, without a new pipeline. Refused
// (false, nothing reset) while events are queued for a worker.
TEST(Pipeline, ResetEstimatorsBetweenTwoClocksGivesTheNewClockAFreshStart) {
  const auto events = stripes(6'000);
  std::vector<Event> before(events.begin(), events.begin() + 4'000);
  std::vector<Event> after(events.begin() + 4'000, events.end());
  const std::int64_t restart = after.front().t_us - before.front().t_us;  // the new clock starts as the old did
  for (Event& e : after) e.t_us -= restart;
  ASSERT_LT(after.back().t_us, before.back().t_us);
  const auto expect_after = bare_estimator(after, kDvs128);
  for (const bool reset : {false, true}) {
    Collector c;
    ee::PacketSource source(kDvs128, events.size());
    ee::Pipeline pipeline(source, &c.sink, engine_options(2, 1, 1, kDvs128));
    source.push(before);
    pipeline.run_for(10'000'000'000);
    ASSERT_EQ(c.events.size(), before.size());
    if (reset) {
      source.push(std::span<const Event>(after.data(), 1));
      pipeline.router().step();  // the event queued for its worker: not between the clocks
      EXPECT_FALSE(pipeline.reset_estimators());
      pipeline.run_for(10'000'000'000);
      c.events.pop_back();
      EXPECT_TRUE(pipeline.reset_estimators());
      source.push(after);
    } else {
      source.push(after);
    }
    source.close();
    EXPECT_TRUE(pipeline.run_for(10'000'000'000).finished);
    const std::vector<AugmentedEvent> got(c.events.end() - static_cast<std::ptrdiff_t>(after.size()), c.events.end());
    if (reset) {
      EXPECT_TRUE(same_bits(got, expect_after));
      EXPECT_EQ(pipeline.stats().rejected(), 1u) << "the new clock's first event, fed before the reset";
    } else {
      EXPECT_TRUE(std::all_of(got.begin(), got.end(), [](const AugmentedEvent& a) { return a.is_noise(); }));
      EXPECT_GT(pipeline.stats().rejected(), after.size() / 2);
    }
  }
}

// A stop requested of a PacketSource ends its stream as close() does: the
// events push() had taken are still estimated and output (3,976 of 5,000
// were neither output nor counted as lost before).
TEST(Pipeline, AStoppedPacketSourceStillDeliversWhatItTook) {
  const auto events = stripes(5'000);
  Collector c;
  ee::PacketSource source(kDvs128, events.size());
  ee::Pipeline pipeline(source, &c.sink, engine_options(2, 1, 1, kDvs128));
  ASSERT_EQ(source.push(events), events.size());
  pipeline.run_for(0);  // one round: one chunk
  ASSERT_GT(source.buffered(), 0u);
  source.request_stop();
  EXPECT_EQ(source.push(std::span<const Event>(events.data(), 3)), 0u);
  while (!pipeline.run_for(10'000'000'000).finished) {
  }
  EXPECT_EQ(source.lost_events(), 3u);
  EXPECT_TRUE(same_bits(c.events, bare_estimator(events, kDvs128)));
}

// stats() is "any thread, any time": a monitor reads the source's lost count
// while the host pushes (a plain integer there was a data race: CI's TSan
// pass runs this test).
TEST(Pipeline, AMonitorReadsTheCountsWhileTheHostPushes) {
  const auto events = stripes(20'000);
  Collector c;
  ee::PacketSource source(kDvs128, 512);  // small: most pushes lose events
  ee::Pipeline pipeline(source, &c.sink, engine_options(2, 1, 1, kDvs128));
  std::atomic<bool> done{false};
  std::uint64_t seen_lost = 0;
  std::thread monitor([&] {
    while (!done.load(std::memory_order_acquire)) seen_lost = std::max(seen_lost, pipeline.stats().source_lost);
  });
  std::size_t taken = 0;
  for (std::size_t i = 0; i < events.size(); i += 1000) {
    taken += source.push(std::span<const Event>(events.data() + i, std::min<std::size_t>(1000, events.size() - i)));
    (void)pipeline.run_for(1'000'000);
  }
  source.close();
  while (!pipeline.run_for(1'000'000'000).finished) {
  }
  done.store(true, std::memory_order_release);
  monitor.join();
  EXPECT_EQ(pipeline.stats().source_lost, events.size() - taken);
  EXPECT_LE(seen_lost, events.size() - taken);
  EXPECT_EQ(c.events.size(), taken);
}

// ---- Real-time settings (realtime_options.h) ---------------------------------

namespace {
using evlife::test::kSanitizerBuild;

// Whether this process may use SCHED_FIFO and pin to CPU 0 (probed on the
// calling thread, then restored).
bool realtime_permitted() {
  const pthread_t self = pthread_self();
  int policy = 0;
  sched_param old{};
  pthread_getschedparam(self, &policy, &old);
  cpu_set_t old_set;
  pthread_getaffinity_np(self, sizeof old_set, &old_set);
  const bool ok = ee::set_fifo_priority(self, 10).empty() && ee::pin_thread(self, 0).empty();
  pthread_setschedparam(self, policy, &old);
  pthread_setaffinity_np(self, sizeof old_set, &old_set);
  return ok;
}

// Runs `fn` in a child process that gave up root's privileges (uid/gid
// nobody: no CAP_SYS_NICE, no CAP_IPC_LOCK) and whose limits allow no
// real-time priority and 64 KiB of locked memory; returns the child's exit code.
template <typename Fn>
int in_unprivileged_child(Fn fn) {
  const pid_t child = fork();
  if (child == 0) {
    const rlimit rtprio{0, 0}, memlock{64 * 1024, 64 * 1024};
    setrlimit(RLIMIT_RTPRIO, &rtprio);
    setrlimit(RLIMIT_MEMLOCK, &memlock);
    if (geteuid() == 0 && (setgroups(0, nullptr) != 0 || setresgid(65534, 65534, 65534) != 0 ||
                           setresuid(65534, 65534, 65534) != 0))
      _exit(90);
    _exit(fn());
  }
  int status = 0;
  waitpid(child, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 100 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}
}  // namespace

// A paced replay's due times stay within the wall clock's range: event times
// at both ends of evlife's range (2^63 us apart), or hours of recording at
// --realtime's lowest speed, overflowed int64 (UB; the event came out due at
// once, about INT64_MIN, instead of never).
TEST(EventClockPacer, DueTimesSaturateInsteadOfOverflowing) {
  using evlife::engine::EventClockPacer;
  EventClockPacer wide(1.0);
  EXPECT_EQ(wide.due_until_us(-evlife::kMaxEventTimeUs, 1000), -evlife::kMaxEventTimeUs);
  EXPECT_EQ(wide.due_at_ns(-evlife::kMaxEventTimeUs + 5), 6000);  // exact in the usual range
  EXPECT_EQ(wide.due_at_ns(evlife::kMaxEventTimeUs), INT64_MAX);
  EXPECT_EQ(wide.due_until_us(-evlife::kMaxEventTimeUs, 1000 + 7000), -evlife::kMaxEventTimeUs + 7);
  EventClockPacer slow(1e-6);  // --realtime=1e-6
  EXPECT_EQ(slow.due_until_us(0, 0), 0);
  EXPECT_EQ(slow.due_at_ns(1), 1'000'000'000);
  EXPECT_EQ(slow.due_at_ns(std::int64_t{3} * 3600 * 1'000'000), INT64_MAX);  // 1.1e22 ns
  EXPECT_EQ(slow.due_at_ns(-std::int64_t{3} * 3600 * 1'000'000), INT64_MIN);
  EventClockPacer fast(1e6);
  EXPECT_EQ(fast.due_until_us(evlife::kMaxEventTimeUs - 10, 0), evlife::kMaxEventTimeUs - 10);
  EXPECT_EQ(fast.due_until_us(evlife::kMaxEventTimeUs - 10, INT64_MAX), INT64_MAX);
}

// A paced replay in packets (the default, 100 us) holds back an event due
// centuries ahead: the packet's rounding of the saturated due time wrapped
// (signed overflow) and released it at once.
TEST(EventClockPacer, APacketOfAnEventDueCenturiesAheadIsNotReleased) {
  for (const auto& [speed, gap_us] : {std::pair{1e-6, std::int64_t{3} * 3600 * 1'000'000},
                                      std::pair{1.0, evlife::kMaxEventTimeUs}}) {
    const std::vector<Event> events{Event{0, 1, 1, 1}, Event{gap_us, 2, 2, 1}};
    for (const std::int64_t packet_us : {std::int64_t{100}, std::int64_t{1000}}) {
      ee::ReplaySource source(events, SensorSize{4, 4}, speed);
      source.set_packet_us(packet_us);
      std::vector<Event> out(4);
      std::size_t pulled = 0;
      for (int k = 0; k < 50; ++k) pulled += source.pull(std::span(out).subspan(pulled));
      EXPECT_EQ(pulled, 1u) << speed << " " << packet_us;  // the first; the second not before its time
    }
  }
}

TEST(Realtime, CpuListParsesRangesAndNamesBadParts) {
  EXPECT_EQ(ee::parse_cpu_list("0,2-4,1"), (std::vector<int>{0, 2, 3, 4, 1}));
  EXPECT_THROW(ee::parse_cpu_list("0,x"), std::invalid_argument);
  EXPECT_THROW(ee::parse_cpu_list("3-1"), std::invalid_argument);
  ee::EngineOptions o;
  o.realtime.rt_priority = 100;
  EXPECT_NE(ee::validate_engine_options(o).find("rt_priority"), std::string::npos);
}

TEST(Realtime, PinnedFifoThreadsAreWhatTheSinkRunsOn) {
  if (!realtime_permitted()) GTEST_SKIP() << "no CAP_SYS_NICE / RLIMIT_RTPRIO here: see RefusedSettings tests";
  const auto events = stripes(20'000);
  std::mutex m;
  std::vector<int> cpus, policies;
  Collector c;
  ee::CallbackSink sink([&](std::span<const AugmentedEvent> s) {
    std::lock_guard lock(m);
    c.events.insert(c.events.end(), s.begin(), s.end());
    cpus.push_back(sched_getcpu());  // the merge runs on a worker or the merger thread
    policies.push_back(sched_getscheduler(0));
  });
  ee::ReplaySource source(events, kDvs128);
  auto options = engine_options(2, 1, 1, kDvs128);
  options.realtime.cpus = {0};
  options.realtime.rt_priority = 10;
  // Not under a sanitizer: mlockall would fault in its terabytes of shadow mappings.
  options.realtime.lock_memory = !kSanitizerBuild;
  ee::Engine engine(source, &sink, options);
  const ee::RunResult r = engine.run();
  munlockall();
  ASSERT_EQ(r.status, ee::RunStatus::completed) << r.message;
  EXPECT_TRUE(same_bits(c.events, bare_estimator(events, kDvs128)));
  ASSERT_FALSE(cpus.empty());
  for (std::size_t i = 0; i < cpus.size(); ++i) {
    EXPECT_EQ(cpus[i], 0);
    EXPECT_EQ(policies[i], SCHED_FIFO);
  }
  EXPECT_NE(r.realtime.find("source:0 worker0:0 worker1:0 merger:0"), std::string::npos) << r.realtime;
  EXPECT_NE(r.realtime.find("SCHED_FIFO 10"), std::string::npos) << r.realtime;
  if (!kSanitizerBuild) {
    EXPECT_NE(r.realtime.find("memory locked"), std::string::npos) << r.realtime;
  }
}

TEST(Realtime, NoSettingsSaysSoAndKeepsDefaultScheduling) {
  const auto events = stripes(5'000);
  std::vector<int> policies;
  ee::CallbackSink sink([&](std::span<const AugmentedEvent>) { policies.push_back(sched_getscheduler(0)); });
  ee::ReplaySource source(events, kDvs128);
  ee::Engine engine(source, &sink, engine_options(1, 1, 1, kDvs128));  // 1 worker: one sink thread at a time
  const ee::RunResult r = engine.run();
  EXPECT_EQ(r.status, ee::RunStatus::completed);
  EXPECT_NE(r.realtime.find("none"), std::string::npos) << r.realtime;
  for (int p : policies) EXPECT_EQ(p, SCHED_OTHER);
}

// Each refused setting: the run ends before any event, status realtime_error,
// the message names the flag and the permission.
void expect_refused(const ee::RealtimeOptions& rt, const char* flag, const char* permission) {
  const int code = in_unprivileged_child([&] {
    const auto events = stripes(5'000);
    std::atomic<std::uint64_t> written{0};
    ee::CallbackSink sink([&](std::span<const AugmentedEvent> s) { written += s.size(); });
    ee::ReplaySource source(events, kDvs128);
    auto options = engine_options(2, 1, 1, kDvs128);
    options.realtime = rt;
    ee::Engine engine(source, &sink, options);
    const ee::RunResult r = engine.run();
    if (r.status != ee::RunStatus::realtime_error) return 1;
    if (r.message.find(flag) == std::string::npos) return 2;
    if (r.message.find(permission) == std::string::npos) return 3;
    if (r.stats.events_in != 0 || written != 0) return 4;
    if (r.exit_code() == 0) return 5;
    return 0;
  });
  EXPECT_EQ(code, 0) << flag << " (1 not refused, 2/3 message, 4 events moved, 5 exit code, 90 setuid)";
}

TEST(Realtime, RefusedFifoPriorityStopsTheRunBeforeAnyEvent) {
  ee::RealtimeOptions rt;
  rt.rt_priority = 20;
  expect_refused(rt, "--rt-priority", "CAP_SYS_NICE");
}

TEST(Realtime, RefusedMemoryLockStopsTheRunBeforeAnyEvent) {
  // The sanitizers' runtimes replace mlockall by a no-op that returns success.
  if (kSanitizerBuild) GTEST_SKIP() << "mlockall is a no-op under the sanitizers";
  ee::RealtimeOptions rt;
  rt.lock_memory = true;
  expect_refused(rt, "--lock-memory", "CAP_IPC_LOCK");
}

TEST(Realtime, CpuOutsideTheAffinityMaskStopsTheRunBeforeAnyEvent) {
  ee::RealtimeOptions rt;
  rt.cpus = {0, 1023};  // no machine here has CPU 1023
  expect_refused(rt, "--cpus", "CPU 1023");
}

TEST(LatencyHistogram, PercentilesWithinBucketResolution) {
  ee::LatencyHistogram h;
  for (std::int64_t v = 1; v <= 100'000; ++v) h.record(v * 10);  // 10 ns .. 1 ms uniform
  EXPECT_EQ(h.count(), 100'000u);
  EXPECT_EQ(h.max_ns(), 1'000'000u);
  const double p50 = static_cast<double>(h.percentile_ns(0.5));
  const double p99 = static_cast<double>(h.percentile_ns(0.99));
  EXPECT_NEAR(p50, 500'000.0, 500'000.0 / 16);
  EXPECT_NEAR(p99, 990'000.0, 990'000.0 / 16);
  for (int i = 0; i < ee::LatencyHistogram::kBuckets - 1; ++i)
    ASSERT_EQ(ee::LatencyHistogram::bucket_of(ee::LatencyHistogram::bucket_upper(i)), i);
}

TEST(LatencyHistogram, CountAboveCountsFromTheBucketOfTheBound) {
  ee::LatencyHistogram h;
  h.record(500'000, 7);    // 0.5 ms
  h.record(2'000'000, 3);  // 2 ms
  h.record(-5);            // clamps to 0
  EXPECT_EQ(h.count_above(1'000'000), 3u);
  EXPECT_EQ(h.count_above(0), 11u);
  EXPECT_EQ(h.count_above(3'000'000), 0u);
  EXPECT_EQ(h.count_above(500'000), 10u);  // the bound's own bucket counts as above
}

// ---- Configuration (not in a core-only build: no config component) -------------

#if __has_include("evlife/config/config.h")
#include "evlife/config/config.h"

#include "evlife/config/config_key.h"

TEST(EngineConfig, SectionDefaultsEqualEngineOptions) {
  const evlife::config::Config c;
  const ee::EngineOptions o;
  EXPECT_EQ(c.engine.workers, o.workers);
  EXPECT_EQ(c.engine.batches_per_worker, o.batches_per_worker);
  EXPECT_TRUE(c.engine.auto_policy);
  EXPECT_EQ(ee::effective_idle_spin_us(o, /*live_source=*/true), ee::kAutoIdleSpinUs);
  EXPECT_EQ(ee::effective_idle_spin_us(o, /*live_source=*/false), 0);
  ee::EngineOptions fixed;
  fixed.idle_spin_us = 7;
  EXPECT_EQ(ee::effective_idle_spin_us(fixed, true), 7);
  EXPECT_EQ(ee::effective_idle_spin_us(fixed, false), 7);
  // SCHED_FIFO threads do not poll unless told to (RT throttling).
  ee::EngineOptions realtime;
  realtime.realtime.rt_priority = 50;
  EXPECT_EQ(ee::effective_idle_spin_us(realtime, true), 0);
  realtime.idle_spin_us = 100;
  EXPECT_EQ(ee::effective_idle_spin_us(realtime, true), 100);
  EXPECT_EQ(o.replay_packet_us, ee::ReplaySource::kDefaultPacketUs);
}

// One table, three readers: every entry is a configuration key with the
// table's range, and the configuration and validate_engine_options() both
// refuse a value just past either end of it (and accept the ends).
TEST(EngineConfig, KeysAndValidationFollowTheOptionTable) {
  int entries = 0;
  ee::for_each_engine_option([&](const evlife::OptionInfo& info, auto field) {
    ++entries;
    const std::string key = "engine." + std::string(info.key);
    const auto* k = evlife::config::find_config_key(key);
    ASSERT_NE(k, nullptr) << key;
    EXPECT_EQ(k->allowed, info.range_text()) << key;
    for (const double v : {info.lo, info.hi, info.lo - 1, info.hi + 1}) {
      const bool inside = info.contains(v);  // -1 too for the "auto" entries
      ee::EngineOptions o;
      field(o) = static_cast<std::remove_reference_t<decltype(field(o))>>(v);
      const std::string err = ee::validate_engine_options(o);
      EXPECT_EQ(err.empty(), inside) << key << " = " << v << ": " << err;
      if (!inside) {
        EXPECT_NE(err.find(key), std::string::npos) << err;
      }
      evlife::config::ConfigBuilder b;
      bool accepted = true;
      try {
        b.set(key, std::to_string(static_cast<long long>(v)), "test");
        (void)b.build();
      } catch (const evlife::config::ConfigError&) {
        accepted = false;
      }
      if (v >= 0 || std::is_signed_v<std::remove_reference_t<decltype(field(o))>>) {
        EXPECT_EQ(accepted, inside) << key << " = " << v;
      }
    }
  });
  EXPECT_GE(entries, 9);
  EXPECT_NE(evlife::config::find_config_key("engine.policy"), nullptr);
}
#endif

// With --to the share of the input read is that of the selected span's
// time: the bytes after its end are never read, so the share of the file's
// bytes stopped short of 100 % (and its ETA counted them).
TEST(ReplaySource, ShareReadWithToIsTheSpansAndEndsAtAll) {
  evlife::io::ReaderOptions input;
  input.to_us = 300'000;  // of stripes.mat's 1.2 s
  auto source = ee::ReplaySource::open_file(std::string(EVLIFE_SHARED_DATA_DIR) + "/reference/stripes.mat",
                                            std::nullopt, 0.0, input);
  std::vector<Event> buffer(4096);
  double mid = -1.0;
  std::size_t events = 0;
  while (source->status() == ee::SourceStatus::ok) {
    events += source->pull(buffer);
    if (mid < 0.0 && source->fraction_read() > 0.0) mid = source->fraction_read();
  }
  EXPECT_EQ(source->status(), ee::SourceStatus::end_of_stream);
  EXPECT_GT(events, 10'000u);
  EXPECT_GT(mid, 0.0);
  EXPECT_LT(mid, 1.0);
  EXPECT_DOUBLE_EQ(source->fraction_read(), 1.0);
}

// ---- Render thread (not in a core-only build: no render component) ---------------

#if __has_include("evlife/render/frame_composer.h")
#include "evlife/engine/render_stage.h"

namespace {
// Records each frame's timestamp and a checksum of its pixels.
class RecordingFrameSink final : public evlife::render::FrameSink {
 public:
  void write(const evlife::render::FrameImage& frame, std::int64_t t_us) override {
    std::uint64_t h = 1469598103934665603ull;  // FNV-1a over the pixels
    for (int r = 0; r < frame.height; ++r) {
      const std::uint8_t* p = frame.bgr + static_cast<std::size_t>(r) * frame.stride_bytes;
      for (std::size_t i = 0; i < static_cast<std::size_t>(frame.width) * 3; ++i) h = (h ^ p[i]) * 1099511628211ull;
    }
    times.push_back(t_us);
    hashes.push_back(h);
  }
  std::vector<std::int64_t> times;
  std::vector<std::uint64_t> hashes;
};

struct RenderRun {
  RecordingFrameSink frames;
  ee::RunResult result;
};

void render_run(const std::vector<Event>& events, bool threaded, RenderRun& run,
                std::int64_t request_t_us = INT64_MIN) {
  ee::ReplaySource source(events, kDvs128);
  auto options = engine_options(2, 1, 1, kDvs128);
  options.render_batches = 4;
  ee::RenderOptions ro;
  ro.fps = 100;  // every 10 ms of event time
  ro.style.scale = 1;
  if (threaded) {
    ee::Engine engine(source, nullptr, options);
    ee::RenderStage stage(*engine.pipeline().state().render_tap, kDvs128, ro, run.frames);
    if (request_t_us != INT64_MIN) stage.request_frame(request_t_us);
    engine.pipeline().attach(stage);
    run.result = engine.run();
  } else {
    ee::Pipeline pipeline(source, nullptr, options);
    ee::RenderStage stage(*pipeline.state().render_tap, kDvs128, ro, run.frames);
    if (request_t_us != INT64_MIN) stage.request_frame(request_t_us);
    pipeline.attach(stage);
    pipeline.run_inline();
    run.result.stats = pipeline.stats();
  }
}
}  // namespace

TEST(RenderStage, FramesFollowTheEventClockAndAreDeterministic) {
  const auto events = stripes(20'000);
  const std::int64_t t0 = events.front().t_us, t_last = events.back().t_us;
  RenderRun inline_run, threaded_run;
  render_run(events, false, inline_run);
  render_run(events, true, threaded_run, t0 + 12'345);
  // A frame every 10 ms of event time from the first event on, up to the last one.
  std::vector<std::int64_t> expect;
  for (std::int64_t t = t0; t <= t_last; t += 10'000) expect.push_back(t);
  ASSERT_FALSE(expect.empty());
  EXPECT_EQ(inline_run.frames.times, expect);
  // Threaded: the same frames (policy block: the render branch misses
  // nothing), plus the requested one in its place.
  std::vector<std::int64_t> with_request = expect;
  with_request.insert(std::upper_bound(with_request.begin(), with_request.end(), t0 + 12'345), t0 + 12'345);
  EXPECT_EQ(threaded_run.frames.times, with_request);
  std::vector<std::uint64_t> hashes_without_request = threaded_run.frames.hashes;
  hashes_without_request.erase(hashes_without_request.begin() + 2);  // the request came third
  EXPECT_EQ(hashes_without_request, inline_run.frames.hashes);
  EXPECT_EQ(threaded_run.result.stats.render_offered, events.size());
  EXPECT_EQ(threaded_run.result.stats.render_dropped, 0u);
  // Frames are not all alike (they show the motion).
  EXPECT_NE(inline_run.frames.hashes.front(), inline_run.frames.hashes.back());
}

// Policy drop: when the render thread is behind, the merger skips its
// events, and with them the clock frames due in their time. Those frames
// are counted (`run` prints them), not lost silently.
TEST(RenderStage, ClockFramesWhoseEventsWereSkippedAreCounted) {
  moodycamel::LightweightSemaphore wake_merger;
  ee::RenderTap tap(1, 64, wake_merger);  // one batch: a second offer finds none free
  ee::RenderOptions ro;
  ro.fps = 100;  // every 10 ms
  ro.style.scale = 1;
  RecordingFrameSink frames;
  ee::RenderStage stage(tap, kDvs128, ro, frames);
  const auto at = [](std::vector<std::int64_t> times) {
    std::vector<AugmentedEvent> events(times.size());
    for (std::size_t i = 0; i < times.size(); ++i) events[i].event = Event{times[i], 5, 5, 1};
    return events;
  };
  ASSERT_TRUE(tap.try_offer(at({0, 25'000})));
  EXPECT_FALSE(tap.try_offer(at({30'000, 55'000})));  // dropped: the render thread has not taken the first
  tap.drop(at({30'000, 55'000}));                      // as the merger does under policy drop
  ASSERT_EQ(stage.step(), ee::StepResult::progressed);
  ASSERT_TRUE(tap.try_offer(at({60'000, 65'000})));    // says that events before it were dropped
  EXPECT_FALSE(tap.try_offer(at({70'000, 95'000})));
  tap.drop(at({70'000, 95'000}));
  tap.close();
  while (stage.step() != ee::StepResult::finished) {
  }
  // 30, 40, 50 ms are drawn without the events skipped from 25 to 60 ms; 60 ms is drawn at the end.
  EXPECT_EQ(frames.times, (std::vector<std::int64_t>{0, 10'000, 20'000, 30'000, 40'000, 50'000, 60'000}));
  EXPECT_EQ(stage.frames_incomplete(), 3u);
  EXPECT_EQ(stage.frames_missed(), 3u);  // 70 .. 90 ms: their events and all after them were skipped
  EXPECT_EQ(stage.frames_not_drawn(), 0u);
}

// A skipped event with a long lifetime belongs in the frames after the gap
// too: they are counted incomplete until it would have ended (before: only
// the frames inside the gap of event time were).
TEST(RenderStage, FramesThatLackALongLivedSkippedEventAreCounted) {
  moodycamel::LightweightSemaphore wake_merger;
  ee::RenderTap tap(1, 64, wake_merger);
  ee::RenderOptions ro;
  ro.fps = 100;  // every 10 ms
  ro.style.scale = 1;
  RecordingFrameSink frames;
  ee::RenderStage stage(tap, kDvs128, ro, frames);
  std::vector<AugmentedEvent> first(2), skipped(1), next(2);
  first[0].event = Event{0, 5, 5, 1};
  first[1].event = Event{5'000, 6, 5, 1};
  skipped[0].event = Event{8'000, 7, 5, 1};
  skipped[0].lifetime_us = 40'000.0f;  // active until 48 ms
  next[0].event = Event{9'000, 8, 5, 1};
  next[1].event = Event{95'000, 9, 5, 1};
  ASSERT_TRUE(tap.try_offer(first));
  ASSERT_FALSE(tap.try_offer(skipped));
  tap.drop(skipped);
  ASSERT_EQ(stage.step(), ee::StepResult::progressed);
  ASSERT_TRUE(tap.try_offer(next));
  tap.close();
  while (stage.step() != ee::StepResult::finished) {
  }
  EXPECT_EQ(frames.times.size(), 10u);  // 0 .. 90 ms
  EXPECT_EQ(stage.frames_incomplete(), 4u);  // 10, 20, 30, 40 ms: without the event of 8 .. 48 ms
  EXPECT_EQ(stage.frames_missed(), 0u);
}
#endif

// ---- The command line --------------------------------------------------------

#ifdef EVLIFE_CLI_PATH
#include "cli_runner.h"

namespace {
const std::filesystem::path kCliLog = std::filesystem::temp_directory_path() / "evlife_test_engine_cli.log";

int run_cli(const std::string& args) {
  return evlife::test::run_cli(EVLIFE_CLI_PATH, args, kCliLog).exit_code;
}

struct RunAndProcess {
  std::string run, process;  // the two output files' bytes
};
// garfield.mat through `evlife run` (2 workers, one tile per polarity) and
// through `evlife process`, each to a FILE`extension`.
RunAndProcess run_and_process(const std::string& extension) {
  const auto dir = std::filesystem::temp_directory_path() / ("evlife_test_engine_cli" + extension);
  std::filesystem::create_directories(dir);
  const std::string in = std::string(EVLIFE_SHARED_DATA_DIR) + "/reference/garfield.mat";
  const std::string a = (dir / ("run" + extension)).string();
  const std::string b = (dir / ("process" + extension)).string();
  RunAndProcess r;
  if (run_cli("run --source file:" + in + " --workers 2 -q -o " + a) == 0 &&
      run_cli("process " + in + " -q -o " + b) == 0) {
    r.run = evlife::test::read_text_file(a);
    r.process = evlife::test::read_text_file(b);
  }
  std::filesystem::remove_all(dir);
  return r;
}
}  // namespace

TEST(RunCommand, WritesTheSameFileAsProcessWithOneTilePerPolarity) {
  const RunAndProcess r = run_and_process(".bin");
  EXPECT_GT(r.run.size(), 202'235u * 32u);
  EXPECT_TRUE(r.run == r.process) << "evlife run and evlife process outputs differ";
}

TEST(RunCommand, WritesHdf5AsProcessDoes) {
  const RunAndProcess r = run_and_process(".h5");
  ASSERT_GT(r.run.size(), 202'235u * 8u);
  EXPECT_EQ(r.run.substr(0, 8), std::string("\x89HDF\r\n\x1a\n", 8));
  EXPECT_EQ(r.run.size(), r.process.size());
}

TEST(RunCommand, DrawsTheAskedInstantsInTimeOrderBesidesTheEventClock) {
  const auto dir = std::filesystem::temp_directory_path() / "evlife_test_engine_at";
  std::filesystem::remove_all(dir);
  const std::string in = std::string(EVLIFE_SHARED_DATA_DIR) + "/reference/stripes.mat";
  auto frames = [&](const std::string& sub) {
    std::vector<std::string> names;
    for (const auto& f : std::filesystem::directory_iterator(dir / sub)) names.push_back(f.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  };
  // Only the instants (stripes starts at t = 0); one past the end is drawn at the end.
  ASSERT_EQ(run_cli("run --source " + in + " -q --render-fps 0 --at 0.5,250ms,9 --frames " + (dir / "a").string()), 0);
  EXPECT_EQ(frames("a"), (std::vector<std::string>{"frame_000000_t0.250000s.png", "frame_000001_t0.500000s.png",
                                                   "frame_000002_t9.000000s.png"}));
  // Mixed with 10 frames/s of the event clock: in time order, 0.3 s only once.
  ASSERT_EQ(run_cli("run --source " + in + " -q --render-fps 10 --at 0.25,0.3 --frames " + (dir / "b").string()), 0);
  const auto b = frames("b");
  ASSERT_GE(b.size(), 6u);
  EXPECT_EQ(std::vector<std::string>(b.begin(), b.begin() + 6),
            (std::vector<std::string>{"frame_000000_t0.000000s.png", "frame_000001_t0.100000s.png",
                                      "frame_000002_t0.200000s.png", "frame_000003_t0.250000s.png",
                                      "frame_000004_t0.300000s.png", "frame_000005_t0.400000s.png"}));
  // The event clock's frames are `evlife render --fps`'s, pixel for pixel
  // (same instants, file names and captions), whatever the workers.
  ASSERT_EQ(run_cli("run --source " + in + " --workers 2 -q --fps 7 --mode compare -o " + (dir / "r.bin").string() +
                    " --frames " + (dir / "c").string()),
            0);
  ASSERT_EQ(run_cli("render " + (dir / "r.bin").string() + " -q --fps 7 --mode compare -o " + (dir / "d").string()), 0);
  const auto c = frames("c");
  EXPECT_EQ(c, frames("d"));
  ASSERT_GE(c.size(), 8u);
  for (const auto& name : c)
    EXPECT_TRUE(evlife::test::read_text_file((dir / "c" / name).string()) ==
                evlife::test::read_text_file((dir / "d" / name).string()))
        << name;
  EXPECT_EQ(run_cli("run --source " + in + " -q --at 0.5"), 2) << "--at without a frame output";
  EXPECT_EQ(run_cli("run --source " + in + " -q --render-fps 0 --video " + (dir / "x.mp4").string()), 2);
  std::filesystem::remove_all(dir);
}

// An event the estimators reject unexamined (here a time beyond 2^62 us) is
// named by `run`'s summary as by `process`'s (run counted it as output only).
TEST(RunCommand, NamesTheRejectedEventsAsProcessDoes) {
  const auto dir = std::filesystem::temp_directory_path() / "evlife_test_engine_rejected";
  std::filesystem::create_directories(dir);
  const std::string in = (dir / "in.txt").string();
  std::ofstream(in) << "0.001 5 5 1\n0.002 6 5 1\n0.003 7 5 0\n5000000000000 5 5 1\n";
  for (const std::string command : {"process", "run"}) {
    const auto r = evlife::test::run_cli(EVLIFE_CLI_PATH, command + " " + in + " --sensor 16x16 -o " +
                                                               (dir / (command + ".bin")).string(),
                                         kCliLog);
    ASSERT_EQ(r.exit_code, 0) << command << ": " << r.output;
    EXPECT_NE(r.output.find("0 outside the sensor, 0 bad polarity, 1 time beyond +-2^62 us"), std::string::npos)
        << command << ": " << r.output;
  }
  std::filesystem::remove_all(dir);
}

TEST(RunCommand, ProgressLinesSayHowFarThroughTheFile) {
  const std::string in = std::string(EVLIFE_SHARED_DATA_DIR) + "/reference/garfield.mat";
  const auto r = evlife::test::run_cli(EVLIFE_CLI_PATH, "run --source " + in + " --stats-period 1ms", kCliLog);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // Once events came in, every progress line starts with the file's share read so far.
  std::size_t lines = 0;
  for (std::size_t at = r.output.find("engine: in "); at != std::string::npos; at = r.output.find("engine: in ", at + 1))
    EXPECT_EQ(r.output.compare(at, 13, "engine: in 0 "), 0) << "no share of the file: " << r.output.substr(at, 80);
  for (std::size_t at = r.output.find(" % of the input, ETA "); at != std::string::npos;
       at = r.output.find(" % of the input, ETA ", at + 1)) {
    const double percent = std::stod(r.output.substr(r.output.rfind(' ', at - 1) + 1));
    EXPECT_GT(percent, 0.0);
    EXPECT_LE(percent, 100.0);
    ++lines;
  }
  EXPECT_GT(lines, 0u) << r.output;
}

// Workers whose estimators would take more memory than the machine has are
// refused up front (each allocates the whole sensor's state, ~80 bytes per
// pixel): a clear exit 2, not the OOM killer after a minute of swapping.
TEST(RunCommand, WorkersThatCannotFitInMemoryAreRefusedUpFront) {
  // 32 workers x (4096 x 4096 x 2 polarities x 41 bytes, planes in whole
  // 2 MiB pages, + the 202 KB RANSAC table) = 44.1 GB.
  const auto available = evlife::test::available_memory_bytes();
  if (!available || *available > 40'000'000'000ULL) GTEST_SKIP() << "this machine has the memory";
  const std::string in = std::string(EVLIFE_SHARED_DATA_DIR) + "/reference/stripes.mat";
  const auto r =
      evlife::test::run_cli(EVLIFE_CLI_PATH, "run " + in + " --sensor 4096x4096 --tiles 4x4 --workers 32 -q", kCliLog);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("32 workers: 44.1 GB), more than the"), std::string::npos) << r.output;
}

TEST(RunCommand, ExitStatusNamesTheFault) {
  EXPECT_EQ(run_cli("run --source file:/nonexistent/x.mat -q"), 3);
  EXPECT_EQ(run_cli("run -q"), 2);
  EXPECT_EQ(run_cli("run --source x.mat --workers 0 -q"), 2);
  EXPECT_EQ(run_cli("run --source x.mat --tiles 2 -q"), 2);
  // Workers beyond the tiles would idle, holding an estimator's memory each: refused, not ignored.
  EXPECT_EQ(run_cli("run --source x.mat --workers 3 -q"), 2);
  EXPECT_EQ(run_cli("run --source x.mat -j 9 --tiles 2x2 -q"), 2);
  // A margin with untiled polarities would change nothing: refused, not ignored.
  const auto margin = evlife::test::run_cli(EVLIFE_CLI_PATH, "run --source x.mat --margin 2 -q", kCliLog);
  EXPECT_EQ(margin.exit_code, 2);
  EXPECT_NE(margin.output.find("--margin 2: with --tiles 1x1 each worker's estimator sees its polarity's whole sensor"),
            std::string::npos) << margin.output;
  EXPECT_EQ(run_cli("run --source x.mat --margin 0 --tiles 2x1 --print-config"), 0);
  EXPECT_EQ(run_cli("run --help"), 0);
  EXPECT_EQ(run_cli("run --source x.mat --rt-priority 0 -q"), 2);
  EXPECT_EQ(run_cli("run --source x.mat --cpus 1,a -q"), 2);
  // A refused real-time setting: exit 5, naming it (CPU 1023 exists nowhere here).
  const std::string in = std::string(EVLIFE_SHARED_DATA_DIR) + "/reference/stripes.mat";
  const auto refused = evlife::test::run_cli(EVLIFE_CLI_PATH, "run --source " + in + " --cpus 1023 -q", kCliLog);
  EXPECT_EQ(refused.exit_code, 5);
  EXPECT_NE(refused.output.find("--cpus: cannot pin a thread to CPU 1023"), std::string::npos) << refused.output;
}

TEST(RunCommand, SummaryStatesTheRealtimeSettingsApplied) {
  const std::string in = std::string(EVLIFE_SHARED_DATA_DIR) + "/reference/stripes.mat";
  const auto plain = evlife::test::run_cli(EVLIFE_CLI_PATH, "run --source " + in + " --stats-period 0", kCliLog);
  EXPECT_EQ(plain.exit_code, 0);
  EXPECT_NE(plain.output.find("realtime: none (default scheduling"), std::string::npos) << plain.output;
  // The recording's time range, as `evlife process` states it for the same file.
  const auto processed = std::filesystem::temp_directory_path() / "evlife_test_engine_range.bin";
  const auto process = evlife::test::run_cli(EVLIFE_CLI_PATH, "process " + in + " -o " + processed.string(), kCliLog);
  std::filesystem::remove(processed);
  const auto range_at = process.output.find("t = ");
  ASSERT_NE(range_at, std::string::npos) << process.output;
  const std::string range = process.output.substr(range_at, process.output.find('\n', range_at) - range_at);
  EXPECT_NE(plain.output.find("time   : " + range + "\n"), std::string::npos) << range << "\n" << plain.output;
  if (!realtime_permitted()) GTEST_SKIP() << "no CAP_SYS_NICE / RLIMIT_RTPRIO here";
  const auto rt = evlife::test::run_cli(
      EVLIFE_CLI_PATH, "run --source " + in + " --stats-period 0 --cpus 0 --rt-priority 5 --lock-memory", kCliLog);
  EXPECT_EQ(rt.exit_code, 0) << rt.output;
  EXPECT_NE(rt.output.find("realtime: cpus source:0 worker0:0 worker1:0 merger:0; SCHED_FIFO 5 (source, "
                           "workers, merger); memory locked"),
            std::string::npos)
      << rt.output;
}
#endif
