// Writes augmented events on a thread of its own, so that `evlife process`
// estimates the next batch while the last one is formatted, compressed and
// written (CSV formatting and HDF5's deflate cost as much as the estimator).
// The mirror of PrefetchReader: fixed memory, `blocks` blocks of
// `block_events` events handed over through lock-free queues; the same bytes
// reach the file in the same order as with the inner writer alone.
#pragma once

#include <atomic>
#include <exception>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <concurrentqueue.h>
#include <lightweightsemaphore.h>

#include "evlife/io/augmented_event_writer.h"
#include "evlife/io/uninitialized_array.h"

namespace evlife::engine {

class WriteBehindWriter final : public io::AugmentedEventWriter {
 public:
  /// Starts the writing thread at once.
  explicit WriteBehindWriter(std::unique_ptr<io::AugmentedEventWriter> inner, std::size_t block_events = 16384,
                             std::size_t blocks = 4);
  /// Closes (flushes) if close() was not called; an error is then lost:
  /// call close() to see it.
  ~WriteBehindWriter() override;
  WriteBehindWriter(const WriteBehindWriter&) = delete;
  WriteBehindWriter& operator=(const WriteBehindWriter&) = delete;

  /// Copies the events into blocks for the thread (waits, without a lock,
  /// while every block is in flight). Throws the inner writer's error
  /// (io::WriteError) once it has failed: the events handed over after its
  /// failure are not written.
  void write(std::span<const AugmentedEvent> events) override;
  /// Hands over the last block, waits until every block is written and the
  /// inner writer closed; throws the first error of either. Idempotent.
  void close() override;
  const std::string& path() const override { return path_; }

 private:
  struct Block {
    io::UninitializedArray<AugmentedEvent> events;
    std::size_t count = 0;
    bool last = false;  // close the inner writer after this block
  };
  void run() noexcept;  // the writing thread
  void hand_over();     // current_ to the thread, a free block into current_
  void rethrow_if_failed() const;

  std::unique_ptr<io::AugmentedEventWriter> inner_;
  std::string path_;
  std::vector<std::unique_ptr<Block>> pool_;
  moodycamel::ConcurrentQueue<Block*> free_;  // thread -> caller
  moodycamel::ConcurrentQueue<Block*> full_;  // caller -> thread
  moodycamel::ProducerToken free_token_{free_};  // constructor, then the thread
  moodycamel::ProducerToken full_token_{full_};  // the caller
  moodycamel::LightweightSemaphore free_ready_;
  moodycamel::LightweightSemaphore full_ready_;
  std::exception_ptr error_;         // the thread's first failure: set before failed_
  std::atomic<bool> failed_{false};  // release/acquire: error_ is visible once this is
  Block* current_ = nullptr;
  bool closed_ = false;
  std::thread thread_;  // last: starts after everything above exists
};

}  // namespace evlife::engine
