// Proves that the engine's stages allocate nothing and take no lock per
// event once built: the allocation probe (tests/probe) counts malloc & co.,
// operator new and pthread_mutex_lock while the stages run a whole recording
// (stepped inline, as the threads step them). Skipped under sanitizers.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "allocation_probe.h"
#include "evlife/engine/pipeline.h"
#include "evlife/engine/replay_source.h"
#include "evlife/io/event_reader.h"

namespace ee = evlife::engine;

namespace {
std::vector<evlife::Event> stripes() {
  auto reader = evlife::io::open_event_reader(std::string(EVLIFE_SHARED_DATA_DIR) +
                                              "/reference/stripes.mat");
  std::vector<evlife::Event> events(100'000);
  std::size_t n = 0;
  while (n < events.size()) {
    const std::size_t got = reader->read(std::span(events.data() + n, events.size() - n));
    if (got == 0) break;
    n += got;
  }
  events.resize(n);
  return events;
}

void expect_no_allocation(ee::OverloadPolicy policy, int tiles, bool render_tap) {
  if (!evlife::test::allocation_probe_available()) GTEST_SKIP() << "sanitizers interpose the allocator";
  const auto events = stripes();
  ee::ReplaySource source(events, {128, 128});
  ee::EngineOptions o;
  o.lifetime.sensor = {128, 128};
  o.workers = 3;
  o.tiles_x = tiles;
  o.tiles_y = tiles;
  o.batch_events = 128;
  o.batches_per_worker = 4;
  o.auto_policy = false;
  o.policy = policy;
  o.render_batches = render_tap ? 2 : 0;
  ee::Pipeline pipeline(source, nullptr, o);
  if (policy == ee::OverloadPolicy::drop)  // as Engine::run's live workers: outputs published every few events
    for (int w = 0; w < pipeline.worker_count(); ++w) pipeline.worker(w).publish_every(ee::TileWorker::kLiveStepEvents);
  evlife::test::AllocationProbe probe;
  // The order in which threads would interleave does not matter; starve the
  // merger now and then so that pools fill and the overload paths run too.
  for (int i = 0; !pipeline.state().input_done.load() || pipeline.merger().step() != ee::StepResult::finished; ++i) {
    pipeline.router().step();
    for (int w = 0; w < pipeline.worker_count(); ++w) pipeline.worker(w).step();
    if (i % 7 == 0) pipeline.drain_merger();  // as a worker thread does after a batch
    if (render_tap && i % 3 == 0) {
      if (ee::RenderBatch* b = pipeline.state().render_tap->try_take()) pipeline.state().render_tap->give_back(b);
    }
  }
  probe.disarm();
  const auto st = pipeline.stats();
  EXPECT_EQ(st.events_in, events.size());
  EXPECT_EQ(st.events_in, st.events_out + st.events_dropped);
  if (policy == ee::OverloadPolicy::drop) {
    EXPECT_GT(st.events_dropped, 0u);
  }
  EXPECT_EQ(probe.allocations(), 0) << "allocations while the stages ran";
  EXPECT_EQ(probe.locks(), 0) << "mutex locks while the stages ran";
}
}  // namespace

TEST(EngineNoAllocation, BlockPolicyTiledWithRenderTap) {
  expect_no_allocation(ee::OverloadPolicy::block, 2, true);
}
TEST(EngineNoAllocation, DropPolicyTiled) { expect_no_allocation(ee::OverloadPolicy::drop, 2, false); }
TEST(EngineNoAllocation, DropPolicyRenderTapPerPolarity) {
  expect_no_allocation(ee::OverloadPolicy::drop, 1, true);
}


// The paced replay's read-ahead: handing blocks between its thread and the
// source thread allocates nothing and locks nothing once built (the inner
// reader here is a memory replay, which does not allocate either).
#include "evlife/engine/prefetch_reader.h"

namespace {
class MemoryReader final : public evlife::io::EventReader {
 public:
  explicit MemoryReader(std::vector<evlife::Event> events) : events_(std::move(events)) {}
  std::size_t read(std::span<evlife::Event> out) override {
    const std::size_t n = std::min(out.size(), events_.size() - pos_);
    std::copy_n(events_.begin() + static_cast<std::ptrdiff_t>(pos_), n, out.begin());
    pos_ += n;
    return n;
  }
  std::optional<evlife::SensorSize> sensor_size() const override { return evlife::SensorSize{128, 128}; }
  std::string_view format_name() const override { return "memory"; }
  const std::string& path() const override { return path_; }

 private:
  std::vector<evlife::Event> events_;
  std::size_t pos_ = 0;
  std::string path_ = "memory";
};
}  // namespace

TEST(EngineNoAllocation, PrefetchReaderHandsBlocksOverWithoutAllocating) {
  if (!evlife::test::allocation_probe_available()) GTEST_SKIP() << "sanitizers interpose the allocator";
  const auto events = stripes();
  ee::PrefetchReader reader(std::make_unique<MemoryReader>(events), 1000, 4);
  std::vector<evlife::Event> buf(777);
  std::size_t total = 0;
  evlife::test::AllocationProbe probe;
  while (const std::size_t n = reader.read(buf)) total += n;
  probe.disarm();
  EXPECT_EQ(total, events.size());
  EXPECT_EQ(probe.allocations(), 0) << "allocations while blocks were handed over";
  EXPECT_EQ(probe.locks(), 0) << "mutex locks while blocks were handed over";
}
