#include "evlife/engine/write_behind_writer.h"

#include <algorithm>

namespace evlife::engine {
namespace {
// One block fills while another is written: fewer would deadlock.
std::size_t pool_blocks(std::size_t asked) { return std::max<std::size_t>(asked, 2); }
}  // namespace

WriteBehindWriter::WriteBehindWriter(std::unique_ptr<io::AugmentedEventWriter> inner, std::size_t block_events,
                                     std::size_t blocks)
    // The queues sized for the pool actually made: enqueueing never allocates.
    : inner_(std::move(inner)), path_(inner_->path()), free_(pool_blocks(blocks), 1, 0),
      full_(pool_blocks(blocks), 1, 0) {
  blocks = pool_blocks(blocks);
  pool_.reserve(blocks);
  for (std::size_t i = 0; i < blocks; ++i) {
    pool_.push_back(std::make_unique<Block>());
    pool_.back()->events = io::UninitializedArray<AugmentedEvent>(std::max<std::size_t>(block_events, 1));
  }
  current_ = pool_[0].get();
  for (std::size_t i = 1; i < blocks; ++i) free_.enqueue(free_token_, pool_[i].get());
  thread_ = std::thread([this] { run(); });
}

WriteBehindWriter::~WriteBehindWriter() {
  try {
    close();
  } catch (...) {
    // Lost, as the header says: a caller that wants the error calls close().
  }
}

void WriteBehindWriter::run() noexcept {
  for (;;) {
    Block* b = nullptr;
    while (!full_.try_dequeue(b)) full_ready_.wait();
    // After a failure the blocks still come back (the caller never waits
    // forever) but are not written: the file ends where the error was.
    if (!failed_.load(std::memory_order_relaxed)) {
      try {
        if (b->count > 0) inner_->write(std::span<const AugmentedEvent>(b->events.data(), b->count));
        if (b->last) inner_->close();
      } catch (...) {
        error_ = std::current_exception();
        failed_.store(true, std::memory_order_release);
      }
    }
    const bool last = b->last;
    b->count = 0;
    b->last = false;
    if (!free_.try_enqueue(free_token_, b)) free_.enqueue(free_token_, b);
    free_ready_.signal();
    if (last) return;
  }
}

void WriteBehindWriter::rethrow_if_failed() const {
  if (failed_.load(std::memory_order_acquire)) std::rethrow_exception(error_);
}

void WriteBehindWriter::hand_over() {
  if (!full_.try_enqueue(full_token_, current_)) full_.enqueue(full_token_, current_);
  full_ready_.signal();
  current_ = nullptr;
  while (!free_.try_dequeue(current_)) free_ready_.wait();
}

void WriteBehindWriter::write(std::span<const AugmentedEvent> events) {
  if (closed_) throw io::WriteError(path_, "write after close");
  rethrow_if_failed();
  while (!events.empty()) {
    const std::size_t n = std::min(events.size(), current_->events.size() - current_->count);
    std::copy_n(events.data(), n, current_->events.data() + current_->count);
    current_->count += n;
    events = events.subspan(n);
    if (current_->count == current_->events.size()) hand_over();
  }
}

void WriteBehindWriter::close() {
  if (!closed_) {
    closed_ = true;
    current_->last = true;
    hand_over();
    thread_.join();
  }
  rethrow_if_failed();
}

}  // namespace evlife::engine
