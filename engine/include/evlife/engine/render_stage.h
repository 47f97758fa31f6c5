// The render thread's stage: takes the merged stream from the RenderTap,
// keeps the active-event map (evlife::algo) up to date and draws a frame
// every 1/fps of the EVENT clock from the first event on (so a replay at any
// speed gives the same frames, those of `evlife render --fps`), plus one frame
// at any requested timestamp. Frames go to a
// render::FrameSink (render/frame_sink.h). No OpenCV in this header: the
// drawing state is in the .cpp. Off the data path: a slow disk here slows only the render branch
// (policy drop) or the output (policy block), never silently.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "evlife/algo/active_event_map.h"
#include "evlife/engine/aux_stage.h"
#include "evlife/engine/notice_ring.h"
#include "evlife/engine/render_tap.h"
#include "evlife/render/fixed_window_map.h"
#include "evlife/render/frame_clock.h"
#include "evlife/render/frame_sink.h"
#include "evlife/render/frame_style.h"

namespace evlife::engine {

struct RenderOptions {
  double fps = 30.0;             ///< frames per second of event time; 0 = only on request
  /// Instants to draw besides (µs from the first event, sorted); those after
  /// the stream's end are drawn at the end.
  std::vector<std::int64_t> at_us;
  std::string mode = "lifetime"; ///< render::parse_view_mode: lifetime | window:30ms | compare
  render::FrameStyle style;
};

class RenderStage final : public AuxStage {
 public:
  /// Throws std::invalid_argument on a bad mode or style.
  RenderStage(RenderTap& tap, SensorSize sensor, const RenderOptions& options, render::FrameSink& sink);
  ~RenderStage() override;
  RenderStage(const RenderStage&) = delete;
  RenderStage& operator=(const RenderStage&) = delete;

  StepResult step() noexcept override;
  moodycamel::LightweightSemaphore& wake() noexcept override { return tap_.wake_render(); }

  /// Asks for one frame at t_us (any thread): drawn once the stream has
  /// passed t_us, or at its end. A later request replaces a pending one.
  void request_frame(std::int64_t t_us) noexcept {
    requested_t_us_.store(t_us, std::memory_order_relaxed);
  }

  /// Ctrl-C: frames not drawn yet are skipped (counted: frames_not_drawn()).
  void request_stop() noexcept override { stop_.store(true, std::memory_order_relaxed); }
  /// The gap warnings of `evlife render` (render::gap_after_frame), one per
  /// call, oldest first, each stretch without events ahead of the clock of
  /// 60+ s and 1000+ frames (a timestamp outlier), said before its empty
  /// frames are drawn; one of render::kEventGapStopFrames frames or more is
  /// skipped (counted in frames_in_skipped_gaps()), as `render` stops before
  /// it. Empty when there is none. Call it from one thread (the monitor).
  std::string take_notice() override;

  std::uint64_t frames_written() const noexcept { return frames_.load(std::memory_order_relaxed); }
  /// Clock frames not drawn because the run was stopped.
  std::uint64_t frames_not_drawn() const noexcept { return not_drawn_.load(std::memory_order_relaxed); }
  /// Clock frames of the stretches without events that were skipped (see take_notice()).
  std::uint64_t frames_in_skipped_gaps() const noexcept { return gap_frames_.load(std::memory_order_relaxed); }
  /// Clock frames due before the run's last event (a dropped one too) that
  /// were never drawn: the events after the last one this thread
  /// received were dropped (policy drop: the workers or the render thread
  /// behind). Known once finished.
  std::uint64_t frames_missed() const noexcept { return missed_.load(std::memory_order_relaxed); }
  /// Frames drawn at an instant whose events were skipped (policy drop, the
  /// render thread behind): blank or partial, counted among frames_written().
  std::uint64_t frames_incomplete() const noexcept { return incomplete_.load(std::memory_order_relaxed); }
  /// The frame sink's error (render thread only, or after the run).
  const std::string& error() const noexcept { return error_; }

 private:
  void emit(std::int64_t t_us) noexcept;
  void feed(const AugmentedEvent& a) noexcept;
  void advance_clock() noexcept;
  void record_gap(const render::EventGap& gap, bool skipped) noexcept;

  static constexpr std::int64_t kNoRequest = INT64_MIN;
  struct Drawing;  // the frame composer and its images (OpenCV)

  RenderTap& tap_;
  ActiveEventMap set_;
  render::FixedWindowMap window_;
  std::unique_ptr<Drawing> drawing_;
  render::FrameSink& sink_;
  double fps_;                                // 0: no clock frames
  std::uint64_t next_frame_ = 0;              // index of the next clock frame
  std::int64_t next_frame_t_us_ = INT64_MIN;  // its instant (render::frame_instant_us)
  std::vector<std::int64_t> at_us_;  // absolute once the first event is seen
  std::size_t next_at_ = 0;
  std::int64_t last_t_us_ = INT64_MIN;
  std::int64_t first_t_us_ = 0;  ///< the first event's: sinks get t from it
  std::atomic<std::int64_t> requested_t_us_{kNoRequest};
  std::atomic<std::uint64_t> frames_{0};
  std::atomic<std::uint64_t> not_drawn_{0};
  std::atomic<std::uint64_t> gap_frames_{0};
  std::atomic<std::uint64_t> missed_{0};
  std::atomic<std::uint64_t> incomplete_{0};
  // A stretch of event time (from, to) whose events were skipped: the frames
  // drawn at instants inside it lack them.
  std::int64_t skipped_from_us_ = INT64_MAX;
  std::int64_t skipped_to_us_ = INT64_MIN;
  std::atomic<bool> stop_{false};
  // The gaps to say, made on the render thread, said by the monitor.
  struct SaidGap {
    render::EventGap gap;
    bool skipped = false;
  };
  NoticeRing<SaidGap> gaps_;
  // A huge stretch's clock frames skipped: from skip_from_frame_ (0: none), skip_frames_ of them.
  std::uint64_t skip_from_frame_ = 0;
  std::uint64_t skip_frames_ = 0;
  std::string error_;
  bool finished_ = false;
};

}  // namespace evlife::engine
