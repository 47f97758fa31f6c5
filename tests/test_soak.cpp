// Overload and soak: a real recording (stripes.mat, DVS128) replayed in an
// endless loop as a live source, as fast as the source thread can copy it —
// many times what the estimator workers can take — for a bounded time. The
// engine must drop (live policy), count every drop, keep its memory flat and
// its latency bounded by its fixed queues, and end cleanly on a stop:
//   events_in == events_out + events_dropped, and the sink got events_out.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "evlife/engine/augmented_sink.h"
#include "evlife/engine/engine.h"
#include "evlife/engine/event_source.h"
#include "evlife/io/event_reader.h"

namespace {

namespace ee = evlife::engine;
using evlife::AugmentedEvent;
using evlife::Event;
using evlife::SensorSize;
using namespace std::chrono_literals;

constexpr SensorSize kDvs128{128, 128};

std::vector<Event> load_recording(const std::string& path) {
  auto reader = evlife::io::open_event_reader(path, {kDvs128, true});
  std::vector<Event> events;
  std::vector<Event> batch(1 << 16);
  while (const std::size_t n = reader->read(batch)) events.insert(events.end(), batch.begin(), batch.begin() + static_cast<std::ptrdiff_t>(n));
  return events;
}

// The recording over and over, each pass shifted in time by the recording's
// span so time keeps going forward. Counts what it hands out.
class LoopingSource final : public ee::EventSource {
 public:
  explicit LoopingSource(const std::vector<Event>& events)
      : events_(events),
        period_us_(events.back().t_us - events.front().t_us + 1) {}

  std::size_t pull(std::span<Event> out) noexcept override {
    if (stop_.load(std::memory_order_relaxed)) {
      status_ = ee::SourceStatus::end_of_stream;
      return 0;
    }
    const std::size_t n = std::min(out.size(), events_.size() - pos_);
    for (std::size_t i = 0; i < n; ++i) {
      out[i] = events_[pos_ + i];
      out[i].t_us += offset_us_;
    }
    pos_ += n;
    if (pos_ == events_.size()) {
      pos_ = 0;
      offset_us_ += period_us_;
    }
    handed_out_ += n;
    return n;
  }
  ee::SourceStatus status() const noexcept override { return status_; }
  std::string error_message() const override { return {}; }
  SensorSize sensor_size() const noexcept override { return kDvs128; }
  ee::SourceKind kind() const noexcept override { return ee::SourceKind::live; }
  std::string describe() const override { return "loop:stripes.mat"; }
  void request_stop() noexcept override { stop_.store(true, std::memory_order_relaxed); }

  std::uint64_t handed_out() const { return handed_out_; }

 private:
  const std::vector<Event>& events_;
  std::int64_t period_us_;
  std::int64_t offset_us_ = 0;
  std::size_t pos_ = 0;
  std::uint64_t handed_out_ = 0;
  ee::SourceStatus status_ = ee::SourceStatus::ok;
  std::atomic<bool> stop_{false};
};

// Counts what reaches it and checks input order (time never goes back).
class CountingSink final : public ee::AugmentedSink {
 public:
  void write(std::span<const AugmentedEvent> events) override {
    for (const AugmentedEvent& a : events) {
      if (a.event.t_us < last_t_us_) ++out_of_order_;
      last_t_us_ = a.event.t_us;
    }
    received_.fetch_add(events.size(), std::memory_order_relaxed);
  }
  std::uint64_t received() const { return received_.load(); }
  std::uint64_t out_of_order() const { return out_of_order_; }

 private:
  std::atomic<std::uint64_t> received_{0};
  std::int64_t last_t_us_ = INT64_MIN;
  std::uint64_t out_of_order_ = 0;
};

std::int64_t resident_bytes() {
  std::ifstream statm("/proc/self/statm");
  std::int64_t size_pages = 0;
  std::int64_t resident_pages = 0;
  statm >> size_pages >> resident_pages;
  return resident_pages * sysconf(_SC_PAGESIZE);
}

TEST(Soak, OverloadedLiveReplayDropsCountedWithFlatMemoryAndBoundedLatency) {
  const std::vector<Event> recording =
      load_recording(std::string(EVLIFE_SHARED_DATA_DIR) + "/reference/stripes.mat");
  ASSERT_GT(recording.size(), 10'000u);

  LoopingSource source(recording);
  CountingSink sink;
  ee::EngineOptions options;
  options.workers = 2;
  options.batch_events = 1024;
  options.batches_per_worker = 8;  // small fixed queues: latency bound ~ 8k events per worker
  options.stats_period_s = 0.0;
  ee::Engine engine(source, &sink, options);

  std::atomic<std::int64_t> rss_warm{0};
  std::atomic<std::int64_t> rss_peak{0};
  std::thread monitor([&] {
    std::this_thread::sleep_for(1s);  // warm-up: pools, queues, estimator state all touched
    rss_warm = resident_bytes();
    for (int i = 0; i < 30; ++i) {  // 3 s more of overload
      std::this_thread::sleep_for(100ms);
      rss_peak = std::max(rss_peak.load(), resident_bytes());
    }
    engine.request_stop();
  });
  const ee::RunResult result = engine.run();
  monitor.join();

  const ee::EngineStats& s = result.stats;
  EXPECT_EQ(result.status, ee::RunStatus::interrupted) << result.message;
  // Counts add up, and every event the source handed out was accepted.
  EXPECT_EQ(s.events_in, source.handed_out());
  EXPECT_EQ(s.events_in, s.events_out + s.events_dropped)
      << "in " << s.events_in << " out " << s.events_out << " dropped " << s.events_dropped;
  EXPECT_EQ(sink.received(), s.events_out);
  EXPECT_EQ(sink.out_of_order(), 0u);
  std::uint64_t dropped_per_worker = 0;
  for (const ee::WorkerStats& w : s.workers) {
    dropped_per_worker += w.dropped;
    EXPECT_LE(w.in_flight_hwm, w.pool_batches) << "a worker's queue grew past its pool";
  }
  EXPECT_EQ(dropped_per_worker + s.dropped_no_order, s.events_dropped)
      << "drops not fully accounted per stage";
  // It really was overloaded: at least twice what it could process was offered.
  EXPECT_GT(s.events_out, 0u);
  EXPECT_GE(s.events_in, 2 * s.events_out) << "not overloaded: the test proves nothing";
  // Memory flat after warm-up: fixed pools, nothing grows with run time.
  EXPECT_LT(rss_peak - rss_warm, 16 << 20)
      << "resident memory grew by " << (rss_peak - rss_warm) / 1024 << " KiB under overload";
  // Latency bounded by the fixed queues, not by the run time (4 s).
  EXPECT_GT(s.latency_count, 0u);
  EXPECT_LT(s.latency_max_us, 2e6) << "p50 " << s.latency_p50_us << " p99 " << s.latency_p99_us;
  EXPECT_LE(s.latency_p99_us, s.latency_max_us);
  std::printf("soak: in %llu out %llu dropped %llu, latency p50 %.0f p99 %.0f max %.0f us, "
              "RSS +%lld KiB after warm-up\n",
              static_cast<unsigned long long>(s.events_in),
              static_cast<unsigned long long>(s.events_out),
              static_cast<unsigned long long>(s.events_dropped), s.latency_p50_us,
              s.latency_p99_us, s.latency_max_us,
              static_cast<long long>((rss_peak - rss_warm) / 1024));
}

}  // namespace
