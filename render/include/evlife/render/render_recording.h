// The frame loop of `evlife render`: one forward pass over a source of
// augmented events, frames drawn at increasing instants (the --at list, or
// --fps from --from to --to) from the incrementally fed active-event set,
// never by re-reading history; written as PNG frames, one PNG or a video.
// Faults are returned, never thrown: the frames before one stay written.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "evlife/render/active_event_set.h"
#include "evlife/render/augmented_source.h"
#include "evlife/render/frame_clock.h"
#include "evlife/render/frame_composer.h"

namespace evlife::render {

/// The highest frame rate written into a video (players and codecs beyond it vary).
inline constexpr double kMaxVideoFps = 60.0;
/// The lowest: a frame each 100 s (FFmpeg's encoders refused 0.001 fps: "the
/// encoder timebase is not set", reported as a video that cannot be opened).
inline constexpr double kMinVideoFps = 0.01;

struct RecordingRenderOptions {
  std::string output;                ///< a folder, FILE.png or a video (.mp4, .avi)
  std::string input;                 ///< the recording's file, if any: no frame is written over it
  bool video = false;                ///< output is a video
  bool single_png = false;           ///< output is one PNG (one --at instant)
  std::vector<std::int64_t> at_us;   ///< instants from the first event, sorted; empty: fps
  double fps = 30.0;                 ///< frames per second of recording time
  std::int64_t from_us = 0;          ///< with fps: first frame, from the first event
  std::optional<std::int64_t> to_us; ///< with fps: last frame (default: the last event)
  std::string mode = "lifetime";     ///< lifetime | window:DUR | compare
  ColorMode color = ColorMode::lifetime;
  std::optional<int> scale;          ///< default: 512 / larger sensor side, >= 1
  bool caption = true;
  bool legend = true;
  bool thinning = true;
  double lifetime_min_us = 300.0;    ///< colour scale
  double lifetime_max_us = 30000.0;
  std::optional<double> video_fps;   ///< written into a video (default fps; at most kMaxVideoFps)
};

struct RecordingRenderResult {
  std::size_t frames = 0;
  std::size_t after_end = 0;          ///< frames at instants after the last event
  std::size_t earlier_frames = 0;     ///< frame files of an earlier run left beside these
  std::optional<std::string> input_fault;
  std::optional<std::string> output_fault;
  bool setup_failed = false;          ///< the output could not be opened: no frame tried
  bool no_events = false;             ///< the source holds no event
  bool stopped = false;               ///< `stop` was seen
  double draw_s = 0.0;                ///< time spent composing frames
  cv::Size frame_size;
  int scale = 1;
  double video_fps = 0;               ///< the rate a video plays at (0: no video)
  ActiveEventSetStats stats;
  std::int64_t first_t_us = 0;        ///< the recording's first event
  std::int64_t last_t_us = 0;         ///< the last event read
  bool exhausted = false;             ///< the whole source was read
};

/// The style render_recording() draws `sensor`'s frames in, and their size
/// (for a caller to weigh a frame against the memory there is before drawing).
FrameStyle frame_style(const RecordingRenderOptions& options, SensorSize sensor);
cv::Size frame_size_for(const RecordingRenderOptions& options, SensorSize sensor);

/// Draws the frames `options` asks for from `source`. `progress(frames,
/// total (0: unknown), t_s)` after each frame; `stop` ends the loop early;
/// `on_gap` at each EventGap long enough to notice (--fps without --to),
/// before its frames are drawn; a gap of kEventGapStopFrames or more ends the
/// drawing before it, as an input fault.
RecordingRenderResult render_recording(
    AugmentedSource& source, const RecordingRenderOptions& options,
    const std::function<void(std::size_t, std::size_t, double)>& progress,
    const std::atomic<bool>* stop = nullptr, const std::function<void(const EventGap&)>& on_gap = {});

}  // namespace evlife::render
