// Compiled only when evlife::render (OpenCV) is part of the build.
#if __has_include("evlife/render/frame_composer.h")
#include "evlife/engine/render_stage.h"

#include <algorithm>
#include <exception>
#include <optional>
#include <stdexcept>

#include "evlife/render/frame_clock.h"
#include "evlife/render/frame_composer.h"
#include "evlife/render/media.h"

namespace evlife::engine {

struct RenderStage::Drawing {
  render::FrameComposer composer;
};

RenderStage::RenderStage(RenderTap& tap, SensorSize sensor, const RenderOptions& options,
                         render::FrameSink& sink)
    : tap_(tap), set_(sensor), window_(sensor),
      drawing_(std::make_unique<Drawing>(
          Drawing{render::FrameComposer(render::parse_view_mode(options.mode), options.style, options.mode)})),
      sink_(sink),
      fps_(options.fps),
      at_us_(options.at_us) {
  if (!(options.fps >= 0) || options.fps > 1e6)
    throw std::invalid_argument("render fps: must be 0 (on request only) or 0 < fps <= 1e6");
}

RenderStage::~RenderStage() = default;

void RenderStage::emit(std::int64_t t_us) noexcept {
  if (!error_.empty()) return;
  if (stop_.load(std::memory_order_relaxed)) {
    not_drawn_.store(not_drawn_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
    return;
  }
  try {
    // Caption and file name: time from the first event, as `evlife render`.
    const std::int64_t rel_us = render::clock_span_us(first_t_us_, t_us);
    sink_.write(render::as_frame(drawing_->composer.compose(set_, window_, t_us, rel_us)), rel_us);
    frames_.store(frames_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
    if (t_us > skipped_from_us_ && t_us < skipped_to_us_)
      incomplete_.store(incomplete_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  } catch (const std::exception& e) {
    error_ = e.what();
  } catch (...) {
    error_ = "unknown error while writing a frame";
  }
}

void RenderStage::advance_clock() noexcept {
  if (++next_frame_ == skip_from_frame_) {  // a huge stretch without events: its frames counted, not drawn
    next_frame_ += skip_frames_;
    gap_frames_.store(gap_frames_.load(std::memory_order_relaxed) + skip_frames_, std::memory_order_relaxed);
    skip_from_frame_ = 0;
  }
  next_frame_t_us_ = render::frame_instant_us(first_t_us_, next_frame_, fps_);
}

void RenderStage::record_gap(const render::EventGap& gap, bool skipped) noexcept {
  gaps_.put(SaidGap{gap, skipped});
}

void RenderStage::feed(const AugmentedEvent& a) noexcept {
  const std::int64_t t = a.event.t_us;
  if (last_t_us_ == INT64_MIN) {  // the first event: the instants count from it
    first_t_us_ = t;
    for (auto& at : at_us_) at = render::clock_add_us(t, at);  // past the clock's end: after the last event
    if (fps_ > 0) next_frame_t_us_ = t;  // frame 0 at the first event, as `evlife render`
  }
  if (fps_ > 0 && t > next_frame_t_us_) {
    // A stretch without events after the next clock frame (which shows the
    // last events before it, and is drawn): every long one is said; one of
    // render::kEventGapStopFrames or more is skipped, counted, not drawn (a
    // timestamp outlier would have the run fill the disk with blank frames).
    const render::GapAhead ahead =
        render::gap_after_frame(0, next_frame_, fps_, render::clock_span_us(first_t_us_, t));
    if (ahead.gap) record_gap(*ahead.gap, ahead.too_long);
    if (ahead.too_long) {
      skip_from_frame_ = next_frame_ + 1;
      skip_frames_ = ahead.gap->empty_frames;
    }
  }
  // Every event up to a frame's instant is in: draw the frames passed, the
  // clock's and the asked-for ones, in time order.
  for (;;) {
    if (fps_ > 0 && t > next_frame_t_us_ && stop_.load(std::memory_order_relaxed)) {
      // Stopped (before or while drawing a gap's frames): skip the clock's
      // frames at once, counted, not one by one (a gap of years is 10^10).
      const std::uint64_t passed = render::frames_before(first_t_us_, next_frame_, t, fps_);
      next_frame_ += passed;
      next_frame_t_us_ = render::frame_instant_us(first_t_us_, next_frame_, fps_);
      not_drawn_.store(not_drawn_.load(std::memory_order_relaxed) + passed, std::memory_order_relaxed);
    }
    const bool clock_due = fps_ > 0 && t > next_frame_t_us_;
    const bool at_due = next_at_ < at_us_.size() && t > at_us_[next_at_];
    if (!clock_due && !at_due) break;
    if (at_due && (!clock_due || at_us_[next_at_] <= next_frame_t_us_)) {
      if (clock_due && at_us_[next_at_] == next_frame_t_us_) advance_clock();  // once
      emit(at_us_[next_at_++]);
    } else {
      emit(next_frame_t_us_);
      advance_clock();
    }
  }
  const std::int64_t req = requested_t_us_.load(std::memory_order_relaxed);
  if (req != kNoRequest && t > req) {
    if (req >= last_t_us_) emit(req);  // an instant already passed cannot be drawn
    std::int64_t expected = req;  // keep a newer request made meanwhile
    requested_t_us_.compare_exchange_strong(expected, kNoRequest);
  }
  set_.feed(a);
  window_.feed(a);
  last_t_us_ = t;
}

std::string RenderStage::take_notice() {
  return gaps_.take_text(
      [this](const SaidGap& said) {
        return said.gap.text(fps_) + (said.skipped ? " Skipped, not drawn (evlife render --from/--to draws them)"
                                                   : " Ctrl-C stops the drawing (the events are still written)");
      },
      "stretches without events");
}

StepResult RenderStage::step() noexcept {
  if (finished_) return StepResult::finished;
  RenderBatch* b = tap_.try_take();
  if (b == nullptr) {
    if (!tap_.closed()) return StepResult::idle;
    b = tap_.try_take();  // an offer made before close() is visible now
    if (b == nullptr) {
      // A clock frame at the last event's instant (no later event passed it)
      // unless an asked-for instant draws it; then the request and the
      // asked-for instants after the end.
      const bool at_draws_it = next_at_ < at_us_.size() && at_us_[next_at_] == next_frame_t_us_;
      if (fps_ > 0 && last_t_us_ != INT64_MIN) {
        // The clock frames through the run's last event (a dropped one too:
        // the workers behind); those past this thread's last event were
        // skipped with its events (counted).
        const std::int64_t run_last =
            std::max({last_t_us_, tap_.last_offered_t_us.load(std::memory_order_relaxed),
                      tap_.last_dropped_t_us.load(std::memory_order_relaxed)});
        const std::uint64_t owed =
            render::frames_before(first_t_us_, next_frame_, run_last == INT64_MAX ? INT64_MAX : run_last + 1, fps_);
        const bool draws_last = next_frame_t_us_ <= last_t_us_ && !at_draws_it;
        if (draws_last) emit(next_frame_t_us_);
        missed_.store(owed - std::min<std::uint64_t>(owed, draws_last || at_draws_it ? 1 : 0),
                      std::memory_order_relaxed);
      }
      const std::int64_t req = requested_t_us_.exchange(kNoRequest);
      if (req != kNoRequest && req >= last_t_us_) emit(req);
      if (last_t_us_ != INT64_MIN)
        while (next_at_ < at_us_.size()) emit(at_us_[next_at_++]);  // after the last event
      try {
        if (error_.empty()) sink_.finish();
      } catch (const std::exception& e) {
        error_ = e.what();
      }
      finished_ = true;
      return StepResult::finished;
    }
  }
  if (b->after_skip && b->count > 0 && last_t_us_ != INT64_MIN) {  // the events between were dropped
    skipped_from_us_ = last_t_us_;
    // Frames are incomplete until the next event received, or later while a
    // dropped event (of this skip or an earlier one) would still be active.
    skipped_to_us_ = std::max({skipped_to_us_, b->events[0].event.t_us, b->skipped_active_until_us + 1});
  }
  for (std::size_t i = 0; i < b->count; ++i) feed(b->events[i]);
  tap_.give_back(b);
  return StepResult::progressed;
}

}  // namespace evlife::engine
#endif
