// The frame loop of `evlife render` (render_recording.h), out of the command line.
#include "evlife/render/render_recording.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>

#include "evlife/io/event_reader.h"
#include "evlife/render/fixed_window_map.h"
#include "evlife/render/frame_clock.h"
#include "evlife/render/frame_sink.h"
#include "evlife/render/media.h"
#include "evlife/render/render_cursor.h"

namespace evlife::render {

FrameStyle frame_style(const RecordingRenderOptions& options, SensorSize sensor) {
  FrameStyle style;
  style.color = options.color;
  style.scale = options.scale.value_or(FrameStyle::default_scale(sensor.width, sensor.height));
  style.caption = options.caption;
  style.legend = options.legend;
  style.lifetime_min_us = options.lifetime_min_us;
  style.lifetime_max_us = options.lifetime_max_us;
  return style;
}

cv::Size frame_size_for(const RecordingRenderOptions& options, SensorSize sensor) {
  return FrameComposer(parse_view_mode(options.mode), frame_style(options, sensor), options.mode).frame_size(sensor);
}

RecordingRenderResult render_recording(
    AugmentedSource& source, const RecordingRenderOptions& options,
    const std::function<void(std::size_t, std::size_t, double)>& progress,
    const std::atomic<bool>* stop, const std::function<void(const EventGap&)>& on_gap) {
  RecordingRenderResult result;
  const SensorSize sensor = source.sensor();
  ActiveEventSet set(sensor, options.thinning);
  FixedWindowMap window(sensor);
  RenderCursor cursor(source, set, &window);

  const FrameStyle style = frame_style(options, sensor);
  FrameComposer composer(parse_view_mode(options.mode), style, options.mode);
  const cv::Size frame_size = composer.frame_size(sensor);

  std::optional<std::int64_t> first_t;
  try {
    first_t = cursor.first_t_us();
  } catch (const io::ReadError& e) {
    result.input_fault = e.what();
    result.setup_failed = true;
    return result;
  }
  if (!first_t) {
    result.no_events = true;
    return result;
  }
  result.first_t_us = *first_t;

  // Output: the frame sinks of frame_sink.h (also those of `evlife run`).
  std::unique_ptr<FrameSink> sink;
  try {
    if (options.video) {
      const double video_fps = std::clamp(options.video_fps.value_or(options.at_us.empty() ? options.fps : 10.0),
                                          kMinVideoFps, kMaxVideoFps);
      result.video_fps = video_fps;
      auto video_sink = std::make_unique<VideoFrameSink>(options.output, video_fps);
      video_sink->check(frame_size.width, frame_size.height);
      sink = std::move(video_sink);
    } else if (options.single_png) {
      sink = std::make_unique<ImageFileFrameSink>(options.output);
    } else {
      sink = std::make_unique<PngFolderFrameSink>(options.output, options.input);
    }
  } catch (const std::runtime_error& e) {
    result.output_fault = e.what();
    result.setup_failed = true;
    return result;
  }

  // Frame instants (relative to the first event).
  std::size_t total = options.at_us.size();
  if (options.at_us.empty() && options.to_us) {
    total = static_cast<std::size_t>(frame_count_through(options.from_us, *options.to_us, options.fps));
  }
  auto frame_time = [&](std::size_t k) -> std::int64_t {
    if (!options.at_us.empty()) return options.at_us[k];
    return frame_instant_us(options.from_us, k, options.fps);
  };

  std::size_t& frames = result.frames;
  std::size_t& after_end = result.after_end;
  auto& input_fault = result.input_fault;
  auto& output_fault = result.output_fault;
  double& draw_s = result.draw_s;
  // The next event of the last gap looked at: each gap is stopped at or said once, every gap (not only the first).
  std::optional<std::int64_t> gap_seen_next;
  for (std::size_t k = 0; !(stop && stop->load(std::memory_order_relaxed)); ++k) {
    if (total > 0 && k >= total) break;
    const std::int64_t rel = frame_time(k);
    std::int64_t t = 0;
    if (__builtin_add_overflow(*first_t, rel, &t)) {  // past the clock's end
      if (options.at_us.empty() && !options.to_us) break;  // --fps: no frame there
      t = INT64_MAX;  // an asked-for instant: after the last event
    }
    try {
      cursor.advance_to(t);
    } catch (const io::ReadError& e) {
      input_fault = e.what();
      break;
    }
    // --fps without --to: stop after the last event.
    if (options.at_us.empty() && !options.to_us && cursor.exhausted() && t > cursor.last_fed_t_us()) break;
    if (cursor.exhausted() && t > cursor.last_fed_t_us()) ++after_end;
    // After this frame (it shows the last events before a stretch without them): stop before a
    // huge stretch, say a long one, each once.
    std::optional<std::string> stop_after_this_frame;
    if (options.at_us.empty() && !options.to_us) {
      const auto next = cursor.next_t_us();
      const std::optional<std::int64_t> next_rel =
          next ? std::optional<std::int64_t>(clock_span_us(*first_t, *next)) : std::nullopt;
      if (next_rel && next_rel != gap_seen_next) {
        const GapAhead ahead = gap_after_frame(options.from_us, k, options.fps, *next_rel);
        if (ahead.too_long) {
          stop_after_this_frame = ahead.gap->text(options.fps) + " Stopped before them (--to T draws through it)";
        } else if (ahead.gap) {
          gap_seen_next = next_rel;
          if (on_gap) on_gap(*ahead.gap);
        }
      }
    }
    const auto d0 = std::chrono::steady_clock::now();
    const cv::Mat& frame = composer.compose(set, window, t, rel);  // caption: time from the first event
    draw_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - d0).count();
    try {
      sink->write(as_frame(frame), rel);  // file names: time from the first event
    } catch (const std::runtime_error& e) {
      output_fault = e.what();
      break;
    }
    ++frames;
    if (progress) progress(frames, total, static_cast<double>(rel) * 1e-6);
    if (stop_after_this_frame) {
      input_fault = *stop_after_this_frame;
      break;
    }
  }
  // Every frame drawn: the event that ended the reading must be followed by
  // a later one (or none), else a corrupt time ended it early (exit 3, as
  // `process` says of the same file, not exit 0 with frames missing events).
  if (!input_fault && !output_fault && !(stop && stop->load(std::memory_order_relaxed))) {
    try {
      cursor.read_past_next();
    } catch (const io::ReadError& e) {
      input_fault = e.what();
    }
  }
  try {
    sink->finish();
  } catch (const std::runtime_error& e) {
    if (!output_fault) output_fault = e.what();
  }
  result.earlier_frames = sink->earlier_frames_left();
  result.stopped = stop && stop->load(std::memory_order_relaxed);
  result.frame_size = frame_size;
  result.scale = style.scale;
  result.stats = set.stats();
  result.last_t_us = cursor.last_fed_t_us();
  result.exhausted = cursor.exhausted();
  return result;
}

}  // namespace evlife::render
