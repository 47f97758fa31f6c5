#include "evlife/render/render_cursor.h"

#include <stdexcept>
#include <string>

namespace evlife::render {

RenderCursor::RenderCursor(AugmentedSource& source, ActiveEventMap& set, FixedWindowMap* window,
                           std::size_t buffer_events)
    : source_(source), set_(set), window_(window), buffer_(std::max<std::size_t>(buffer_events, 2)) {}

bool RenderCursor::refill() {
  if (ended_) return false;
  pos_ = 0;
  count_ = source_.read(buffer_);
  if (count_ == 0) ended_ = true;
  return count_ > 0;
}

std::optional<std::int64_t> RenderCursor::first_t_us() {
  if (events_fed_ > 0) throw std::logic_error("RenderCursor::first_t_us after advancing");
  if (pos_ == count_ && !refill()) return std::nullopt;
  return buffer_[pos_].event.t_us;
}

void RenderCursor::advance_to(std::int64_t t_us) {
  if (t_us < cursor_t_us_) {
    throw std::invalid_argument("render times must not decrease (asked " + std::to_string(t_us) +
                                " us after " + std::to_string(cursor_t_us_) + " us)");
  }
  cursor_t_us_ = t_us;
  for (;;) {
    if (pos_ == count_ && !refill()) return;
    while (pos_ < count_) {
      const AugmentedEvent& a = buffer_[pos_];
      if (a.event.t_us > t_us) return;
      set_.feed(a);
      if (window_ != nullptr) window_->feed(a.event);
      last_fed_t_us_ = a.event.t_us;
      ++events_fed_;
      ++pos_;
    }
  }
}

void RenderCursor::read_past_next() {
  if (pos_ + 1 != count_ || ended_) return;  // none next, or its successor is read (and checked) already
  buffer_[0] = buffer_[pos_];  // kept: the next event, then what the source has after it
  pos_ = 0;
  count_ = 1;
  const std::size_t more = source_.read(std::span(buffer_).subspan(1));
  count_ += more;
  if (more == 0) ended_ = true;
}

}  // namespace evlife::render
