// Reads a recording ahead on a thread of its own, as a camera's USB thread
// receives transfers while the engine works: a paced replay's source thread
// then never stalls on decoding (a 20 ms slice of a synthetic scene, a zlib
// block of a .mat file), which would otherwise show as latency and, past the
// queues, as drops. Fixed memory: `blocks` blocks of `block_events` events.
#pragma once

#include <atomic>
#include <cstdint>
#include <exception>
#include <memory>
#include <thread>
#include <vector>

#include <concurrentqueue.h>
#include <lightweightsemaphore.h>

#include "evlife/io/event_reader.h"
#include "evlife/io/uninitialized_array.h"

namespace evlife::engine {

class PrefetchReader final : public io::EventReader {
 public:
  /// Starts the read-ahead thread at once.
  explicit PrefetchReader(std::unique_ptr<io::EventReader> inner, std::size_t block_events = 4096,
                          std::size_t blocks = 8);
  ~PrefetchReader() override;  // stops and joins the thread
  PrefetchReader(const PrefetchReader&) = delete;
  PrefetchReader& operator=(const PrefetchReader&) = delete;

  /// As the inner reader's: the events in file order, then 0 at the end; a
  /// read error is thrown after every event before it was returned. Waits
  /// (without a lock) when the read-ahead is behind.
  std::size_t read(std::span<Event> out) override;

  std::optional<SensorSize> sensor_size() const override { return sensor_; }
  std::string_view format_name() const override { return format_; }
  const std::string& path() const override { return path_; }
  /// The inner reader's counters as of the events returned so far (every
  /// skipped record is shown, whichever reader wraps it).
  std::uint64_t skipped_record_count() const override { return skipped_; }
  std::uint64_t trigger_count() const override { return triggers_; }
  std::vector<io::SkippedKindCount> skipped_record_kinds() const override { return kinds_; }
  /// As the inner reader stated them when this was built.
  std::vector<io::ContainerStream> streams() const override { return streams_; }
  std::uint64_t bytes_consumed() const override { return bytes_; }

  /// Kinds of skipped records a block carries without allocating (the
  /// formats have at most 16; more are still carried, allocating).
  static constexpr std::size_t kMaxSkippedKinds = 32;

 private:
  struct Block {
    io::UninitializedArray<Event> events;
    std::size_t count = 0;        // 0: end of stream or error, nothing follows
    std::exception_ptr error;     // the inner reader's, when it threw
    std::uint64_t skipped = 0;    // inner counters after this block
    std::uint64_t triggers = 0;
    std::vector<io::SkippedKindCount> kinds;  // capacity kMaxSkippedKinds, reserved once
    std::uint64_t bytes = 0;
  };
  void run() noexcept;  // the read-ahead thread

  std::unique_ptr<io::EventReader> inner_;
  std::optional<SensorSize> sensor_;
  std::string format_;
  std::string path_;
  std::vector<io::ContainerStream> streams_;
  std::vector<std::unique_ptr<Block>> pool_;
  moodycamel::ConcurrentQueue<Block*> free_;  // consumer -> read-ahead thread
  moodycamel::ConcurrentQueue<Block*> full_;  // read-ahead thread -> consumer
  // Explicit producers sized for every block: enqueueing never allocates.
  moodycamel::ProducerToken free_token_{free_};  // constructor, then the consumer
  moodycamel::ProducerToken full_token_{full_};  // the read-ahead thread
  moodycamel::LightweightSemaphore free_ready_;
  moodycamel::LightweightSemaphore full_ready_;
  std::atomic<bool> stop_{false};
  Block* current_ = nullptr;
  std::size_t pos_ = 0;
  std::uint64_t skipped_ = 0;
  std::uint64_t triggers_ = 0;
  std::vector<io::SkippedKindCount> kinds_;  // reserved: copying a block's never allocates
  std::uint64_t bytes_ = 0;
  // The read-ahead thread's: the inner reader's kinds, asked again only when
  // its skipped count changed (the one allocation, on that thread).
  std::uint64_t inner_skipped_ = 0;
  std::vector<io::SkippedKindCount> inner_kinds_;
  std::thread thread_;  // last: starts after everything above exists
};

}  // namespace evlife::engine
