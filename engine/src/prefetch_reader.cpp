#include "evlife/engine/prefetch_reader.h"

#include <algorithm>

namespace evlife::engine {

PrefetchReader::PrefetchReader(std::unique_ptr<io::EventReader> inner, std::size_t block_events,
                               std::size_t blocks)
    : inner_(std::move(inner)),
      sensor_(inner_->sensor_size()),
      format_(inner_->format_name()),
      path_(inner_->path()),
      streams_(inner_->streams()),
      free_(blocks, 1, 0),
      full_(blocks, 1, 0) {
  pool_.reserve(blocks);
  for (std::size_t i = 0; i < blocks; ++i) {
    pool_.push_back(std::make_unique<Block>());
    pool_.back()->events = io::UninitializedArray<Event>(block_events);
    pool_.back()->kinds.reserve(kMaxSkippedKinds);
    free_.enqueue(free_token_, pool_.back().get());
  }
  kinds_.reserve(kMaxSkippedKinds);
  thread_ = std::thread([this] { run(); });
}

PrefetchReader::~PrefetchReader() {
  stop_.store(true, std::memory_order_relaxed);
  free_ready_.signal();
  thread_.join();
}

void PrefetchReader::run() noexcept {
  while (!stop_.load(std::memory_order_relaxed)) {
    Block* b = nullptr;
    if (!free_.try_dequeue(b)) {
      free_ready_.wait(10'000);  // the consumer returns blocks; re-check stop
      continue;
    }
    try {
      b->count = inner_->read(std::span<Event>(b->events.data(), b->events.size()));
    } catch (...) {
      b->count = 0;
      b->error = std::current_exception();
    }
    b->skipped = inner_->skipped_record_count();
    b->triggers = inner_->trigger_count();
    if (b->skipped != inner_skipped_) {
      inner_skipped_ = b->skipped;
      inner_kinds_ = inner_->skipped_record_kinds();
    }
    b->kinds.assign(inner_kinds_.begin(), inner_kinds_.end());
    b->bytes = inner_->bytes_consumed();
    const bool last = b->count == 0;
    if (!full_.try_enqueue(full_token_, b)) full_.enqueue(full_token_, b);
    full_ready_.signal();
    if (last) return;
  }
}

std::size_t PrefetchReader::read(std::span<Event> out) {
  std::size_t got = 0;
  while (got < out.size()) {
    if (current_ == nullptr) {
      if (!full_.try_dequeue(current_)) {
        current_ = nullptr;
        if (got > 0) return got;  // hand over what is here rather than wait
        full_ready_.wait();
        continue;
      }
      pos_ = 0;
      skipped_ = current_->skipped;
      triggers_ = current_->triggers;
      kinds_.assign(current_->kinds.begin(), current_->kinds.end());
      bytes_ = current_->bytes;
    }
    if (current_->count == 0) {  // the last block, kept: every later call ends the same way
      if (got > 0) return got;
      if (current_->error) std::rethrow_exception(current_->error);
      return 0;
    }
    const std::size_t n = std::min(out.size() - got, current_->count - pos_);
    std::copy_n(current_->events.data() + pos_, n, out.data() + got);
    got += n;
    pos_ += n;
    if (pos_ == current_->count) {
      if (!free_.try_enqueue(free_token_, current_)) free_.enqueue(free_token_, current_);
      free_ready_.signal();
      current_ = nullptr;
    }
  }
  return got;
}

}  // namespace evlife::engine
