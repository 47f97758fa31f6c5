// Synthetic event scenes with per-event ground truth: the yardstick of the
// lifetime estimator (tests, benches) and a camera-free event source (engine,
// `evlife synth`).
//
// Model: bright bars on a dark background. An event fires when an edge crosses
// a pixel centre (pixel (x, y) has its centre at (x, y)); the leading edge of a
// bar gives ON (+1), the trailing edge OFF (-1). True lifetime = 1 / normal
// speed of the edge at that pixel and time; true direction = unit normal of
// the edge, pointing where it moves. Timestamps get Gaussian jitter (sigma,
// truncated at 4 sigma) and are then sorted, so the output is time-ordered.
// Background noise: uniform over pixels and time, random polarity.
//
// Deterministic: the same spec gives the same events bit for bit (own RNG and
// own Gaussian: std:: distributions differ between standard libraries; only
// libm's log/cos/atan2 could differ in the last bit across platforms). The
// scene is produced in fixed time slices, so streaming it (SyntheticSceneReader)
// and generating it at once (generate_scene) give identical output.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "evlife/algo/event.h"
#include "evlife/io/event_reader.h"

namespace evlife::io {

/// Half-open pixel rectangle [x0, x1) x [y0, y1); a feature only fires inside
/// its region. x1/y1 <= 0 mean "to the sensor edge".
struct PixelRegion {
  int x0 = 0;
  int y0 = 0;
  int x1 = 0;
  int y1 = 0;
};

/// Periodic bright bars (a square-wave grating) translating along a normal.
struct GratingSpec {
  double direction_deg = 0.0;    ///< direction of motion; 0 = +x, 90 = +y (down the rows)
  double lifetime_us = 1000.0;   ///< 1 / normal speed: time the edge needs per pixel
  double period_px = 16.0;       ///< distance between successive leading edges
  double bar_width_px = 8.0;     ///< leading (ON) to trailing (OFF) edge, < period
  double phase_px = 0.0;         ///< offset of the pattern along the normal
  PixelRegion region;
  std::int64_t t_begin_us = 0;   ///< motion (hence events) only within [t_begin, t_end)
  std::int64_t t_end_us = std::numeric_limits<std::int64_t>::max();
};

/// A bright bar through a centre of rotation, turning with an angular speed that
/// ramps linearly from omega_start to omega_end over [0, ramp_us] and then stays
/// (the paper's quadrotor flip reaches 1200 deg/s). Lifetime at radius r is
/// 1 / (omega * sqrt(r^2 - (w/2)^2)): it diverges near the centre, so events
/// closer than min_scored_radius_px are marked not scorable.
struct RotatingBarSpec {
  double centre_x = 0.0;
  double centre_y = 0.0;
  double bar_width_px = 6.0;
  double start_angle_deg = 0.0;
  double omega_start_deg_s = 150.0;   ///< > 0
  double omega_end_deg_s = 1200.0;    ///< > 0
  double ramp_us = 1.0e6;
  double min_scored_radius_px = 12.0;
  PixelRegion region;
};

struct SceneSpec {
  SensorSize sensor{240, 180};
  std::int64_t duration_us = 1'000'000;
  std::vector<GratingSpec> gratings;
  std::vector<RotatingBarSpec> bars;
  double noise_rate_hz_per_px = 1.0;  ///< background events per pixel per second
  double jitter_sigma_us = 20.0;      ///< Gaussian sigma of timestamp jitter (truncated at 4 sigma)
  std::uint64_t seed = 1;
  std::int64_t slice_us = 20'000;     ///< generation slice (part of the determinism contract)
};

/// Ground truth of one event (same index as the event).
struct EventTruth {
  double t_true_us = 0.0;     ///< crossing time before jitter and rounding
  double lifetime_us = 0.0;   ///< 1 / normal speed; 0 for noise
  double nx = 0.0;            ///< unit normal, direction of motion; 0 for noise
  double ny = 0.0;
  double travel_px = 0.0;     ///< how far the edge has moved since its motion began:
                              ///< a window needs ~N/2 px of travel before it holds support
  std::int16_t feature = -1;  ///< index into SyntheticScene::feature_names; -1 = noise
  std::uint16_t margin_px = 0;  ///< Chebyshev distance to the edge of the feature's region
                                ///< (noise: of the sensor): an N x N window fits when >= N/2
  bool is_noise = false;
  bool scorable = true;       ///< false where the local time surface is not a plane
                              ///< (near a rotation centre)
};

struct SyntheticScene {
  SceneSpec spec;
  std::vector<Event> events;        ///< time-ordered
  std::vector<EventTruth> truth;    ///< truth[i] describes events[i]
  std::vector<std::string> feature_names;  ///< gratings first, then bars
};

/// Returns "" when the spec is usable, else a message naming the field.
std::string validate_scene_spec(const SceneSpec& spec);

/// Human-readable names of the features (gratings first, then bars).
std::vector<std::string> scene_feature_names(const SceneSpec& spec);

/// Generates the whole scene in memory. Throws std::invalid_argument on a bad spec.
SyntheticScene generate_scene(const SceneSpec& spec);

// ---- Presets (the scene families of the accuracy test and `evlife synth`) ----

/// Tiles of gratings (~60 px), each with its own direction (golden-angle steps
/// from 23 deg: spread over 0..360, mostly off the axes) and lifetime (300 us .. 20 ms,
/// log-spaced); each tile moves during the last `max_passes` bar periods of the
/// scene (or all of it) so fast tiles do not dominate the event count. Pixels
/// see repeated passes, so windows hold stale events of earlier bars.
SceneSpec edges_scene(SensorSize sensor, std::int64_t duration_us, std::uint64_t seed,
                      int max_passes = 6);

/// One bar rotating about the sensor centre, 150 -> 1200 deg/s over the duration.
SceneSpec rotating_bar_scene(SensorSize sensor, std::int64_t duration_us, std::uint64_t seed);

/// Left half: a slow grating (top) and a fast one (bottom), each moving for
/// three bar periods; right half: a bar rotating 150 -> 1200 deg/s.
SceneSpec mixed_scene(SensorSize sensor, std::int64_t duration_us, std::uint64_t seed);

/// Many edges for throughput benches: 80 px tiles of gratings over the whole
/// sensor (e.g. 1280 x 720), lifetimes 300 us .. 20 ms, running all the time.
SceneSpec large_scene(SensorSize sensor, std::int64_t duration_us, std::uint64_t seed);

/// Preset by name: "edges", "bar", "mixed", "large". nullopt for an unknown name.
std::optional<SceneSpec> scene_preset(std::string_view name, SensorSize sensor,
                                      std::int64_t duration_us, std::uint64_t seed);

/// Streams a scene slice by slice with memory bounded by one slice (slice_us of
/// events, ~80 B each, plus the jitter carry-over): a camera-free source of
/// any length. Output equals generate_scene().
class SyntheticSceneReader : public EventReader {
 public:
  /// Throws std::invalid_argument on a bad spec.
  explicit SyntheticSceneReader(SceneSpec spec);

  std::size_t read(std::span<Event> out) override;

  /// Like read(), also copying the truth of each event (truth.size() >= out.size()).
  std::size_t read_with_truth(std::span<Event> out, std::span<EventTruth> truth);

  std::optional<SensorSize> sensor_size() const override { return spec_.sensor; }
  std::string_view format_name() const override { return "synthetic"; }
  const std::string& path() const override { return name_; }
  const SceneSpec& spec() const noexcept { return spec_; }

 private:
  struct Pending {
    Event event;
    EventTruth truth;
    std::uint64_t sequence;  // generation order: the tie-break of equal timestamps
  };
  void generate_next_slice();

  SceneSpec spec_;
  std::string name_ = "<synthetic>";
  std::int64_t next_slice_ = 0;
  std::int64_t slice_count_ = 0;
  std::uint64_t sequence_ = 0;
  std::vector<Pending> pending_;  // sorted by (t, sequence)
  std::vector<Pending> slice_;    // scratch: the slice being generated
  std::size_t ready_ = 0;         // pending_[0, ready_) can no longer be preceded
  std::size_t emitted_ = 0;       // pending_[0, emitted_) were handed out
};

}  // namespace evlife::io
