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
// Optional DVS pixel model (SceneSpec::pixel, off by default: the ideal model
// above is unchanged bit for bit): an edge is a log-intensity step spread over
// a blurred profile; each pixel fires one event per (mismatched) threshold
// crossed, with latency, latency jitter and a refractory period, so an edge
// gives a burst of events; plus hot pixels. See PixelModel.
//
// Deterministic: the same spec gives the same events bit for bit (own RNG and
// own Gaussian: std:: distributions differ between standard libraries; only
// libm's log/cos/atan2 could differ in the last bit across platforms). The
// scene is produced in fixed time slices, so streaming it (SyntheticSceneReader)
// and generating it at once (generate_scene) give identical output.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "evlife/algo/event.h"
#include "evlife/io/available_memory.h"
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

/// A DVS pixel (Lichtsteiner et al., JSSC 2008, the DVS128; simulators v2e,
/// Delbruck et al. 2021, and ESIM, Rebecq et al. 2018). Per crossing of a pixel
/// by an edge whose centre passes at t_c with lifetime tau, the pixel's log
/// intensity follows L(t) = C * clamp((t - t_c) / (blur * tau) + 1/2, 0, 1)
/// (OFF edges mirrored). The pixel starts with a residual r0 in [0, theta)
/// already accumulated (reference -r0); it fires at each time L reaches
/// reference + theta, the event is stamped latency later, the pixel resets then
/// (reference = L) and stays in reset for the refractory period. A crossing
/// thus gives a burst of ~C/theta events spread over ~blur * tau around t_c,
/// fewer when latency + refractory period are long against the transit.
/// All draws of a crossing are hashes of (seed, feature, pixel, polarity,
/// crossing): a burst does not depend on how the scene is sliced.
/// With the model on, SceneSpec::jitter_sigma_us is not used (latency jitter
/// replaces it); background activity stays SceneSpec::noise_rate_hz_per_px.
struct PixelModel {
  bool enabled = false;
  /// Log-intensity step of an edge (ln units). Bright bar on a dark background:
  /// 0.5 = a 1.65:1 intensity ratio, a printed pattern under office light.
  double contrast_log = 0.5;
  /// Each feature's contrast = contrast_log * (1 + spread * u), u in [-1, 1)
  /// from a hash of the feature index: scenes hold edges of different contrast.
  double contrast_spread = 0.4;
  /// Nominal ON and OFF threshold (ln units). v2e default 0.2; ESIM's Python
  /// simulator 0.15; issue 11: 0.15-0.3 on real sensors (bias-set).
  double threshold_log = 0.2;
  /// Fixed-pattern mismatch of the threshold per pixel and polarity (sigma, ln
  /// units). v2e default 0.03; ESIM default 0.021; DVS128: 2.1 % contrast.
  double threshold_mismatch_sigma = 0.03;
  /// Width of the edge profile in pixels (optics, pixel aperture, motion blur
  /// in the photoreceptor): L ramps over edge_blur_px * tau around t_c.
  double edge_blur_px = 1.5;
  /// Pixel latency (us), from the threshold crossing to the timestamp: the
  /// centre of the Gaussian below (its truncation at 0 raises the mean when
  /// the jitter is a good part of it: 500 +- 300 us gives 531 us).
  /// DVS128: 15 us in bright light, growing as the photocurrent falls
  /// (Lichtsteiner 2008);
  /// the readout of a busy array adds tens of us.
  double latency_us = 80.0;
  /// Per-event latency sigma (us), Gaussian truncated to [0, mean + 4 sigma].
  double latency_jitter_us = 40.0;
  /// Refractory period (us): the pixel stays in reset this long after an event.
  /// v2e default 500 us; ESIM default 100 us; set by a bias on real sensors.
  double refractory_us = 200.0;
  /// Share of pixels that are hot (at least one when > 0): they fire on their
  /// own at hot_pixel_rate_hz with random polarity (noise in the truth).
  double hot_pixel_fraction = 1e-4;
  double hot_pixel_rate_hz = 20.0;
  /// Photoreceptor bandwidth (3 dB cutoff, Hz) on the bright side of an edge;
  /// 0 = unlimited (the pixel follows the edge's log intensity at once). The
  /// photoreceptor is a low-pass filter whose bandwidth grows with the
  /// photocurrent (Lichtsteiner 2008; v2e's IIR filter: time constant
  /// 1 / (2 pi cutoff_hz x relative intensity), default 300 Hz at full white,
  /// `--dvs_params noisy` 30 Hz), so an ON edge (to the bright side) is
  /// followed with time constant 1 / (2 pi cutoff_hz), an OFF edge (to the
  /// dark side, e^-C as bright) e^C times slower. In dim light it is ~10-300 Hz, a time
  /// constant of 0.5-16 ms, so the pixel's log intensity approaches each edge
  /// exponentially, the threshold crossings spread over that time constant
  /// and a burst lasts far longer than its edge's transit. First order, as
  /// v2e's; each crossing starts from a settled photoreceptor (the model holds
  /// while the time constant is shorter than the time between two edges at a
  /// pixel).
  double cutoff_hz = 0.0;
  /// Timestamp resolution (us) of the readout: stamps are floored to a
  /// multiple (every event's: edges, hot pixels, background). 0 or 1 = 1 us,
  /// as DVS128 / DAVIS. A frame-based emulator stamps at its frame interval
  /// (v2e: the upsampled frame rate); an arbitrated readout under load groups
  /// events in steps (evt3_sample.raw: ~101 us steps at ~25 M events/s).
  double timestamp_quantum_us = 0.0;
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
  PixelModel pixel;                   ///< off: ideal pixels (one event per crossing)
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
  std::uint8_t burst_index = 0;  ///< pixel model: 0 = first event of its crossing's burst
  bool is_noise = false;
  bool is_hot = false;        ///< from a hot pixel (is_noise is true too)
  bool scorable = true;       ///< false where the local time surface is not a plane
                              ///< (near a rotation centre)
};

struct SyntheticScene {
  SceneSpec spec;
  std::vector<Event> events;        ///< time-ordered
  std::vector<EventTruth> truth;    ///< truth[i] describes events[i]
  std::vector<std::string> feature_names;  ///< gratings first, then bars
  bool complete = true;  ///< false: the generation's stop() ended it early
  std::size_t generated_events = 0;  ///< when stopped: the events generated by then (not all kept: textured_scene.h)
};

/// Asked between slices or tiles of a long generation (Ctrl-C in Python):
/// true ends it early, with SyntheticScene::complete false.
using GenerationStop = std::function<bool()>;

/// Returns "" when the spec is usable, else a message naming the field.
std::string validate_scene_spec(const SceneSpec& spec);

/// Events per second of the background: noise and hot pixels (mean). The
/// part of a scene that grows with the sensor and the rates without bound.
double background_events_per_s(SensorSize sensor, double noise_rate_hz_per_px, const PixelModel& pixel);

/// What SyntheticSceneReader holds at once, for a refusal before it starts:
/// a slice's background events at ~220 B each (event, truth, sequence, the
/// slice's sort and merge: 726 MB peak for 3.3 M background events per slice,
/// `evlife synth --noise-rate 10000 --sensor 128x128 --duration 0.04 -o x.h5`).
std::uint64_t scene_reader_memory_bytes(const SceneSpec& spec);


/// Human-readable names of the features (gratings first, then bars).
std::vector<std::string> scene_feature_names(const SceneSpec& spec);

/// Generates the whole scene in memory (`stop` asked after each slice: the
/// slices before it are kept). Throws std::invalid_argument on a bad spec.
SyntheticScene generate_scene(const SceneSpec& spec, const GenerationStop& stop = {});

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

/// Left two thirds: the tiles of edges_scene; right third: a bar rotating
/// 150 -> 1200 deg/s. Translating and rotating edges in one scene (the pixel
/// model's test scene, e.g. on a DAVIS346's 346 x 260).
SceneSpec edges_and_bar_scene(SensorSize sensor, std::int64_t duration_us, std::uint64_t seed);

/// Preset by name: "edges", "bar", "mixed", "large", "edges-bar". nullopt for an unknown name.
std::optional<SceneSpec> scene_preset(std::string_view name, SensorSize sensor,
                                      std::int64_t duration_us, std::uint64_t seed);

// ---- Pixel settings ----

/// A DVS in normal (office, ~100s of lux) light: latency 80 +- 40 us,
/// refractory 200 us; background activity kDvsNormalNoiseRateHzPerPx.
PixelModel dvs_pixel_normal();

/// A DVS in dim light: the photocurrent is small, so latency and its jitter
/// grow to hundreds of us (Lichtsteiner 2008: latency grows as light falls)
/// and the refractory period is set longer; background activity higher.
PixelModel dvs_pixel_dim();

/// Background activity of the two settings (events per pixel per second):
/// DVS128 and DAVIS report ~0.1-1 Hz at room temperature, more in the dark.
inline constexpr double kDvsNormalNoiseRateHzPerPx = 0.2;
inline constexpr double kDvsDimNoiseRateHzPerPx = 1.0;

/// A pixel-model parameter set by name (`evlife synth --NAME V`,
/// `accuracy_sweep --pixel NAME=V`) and the range it accepts.
struct PixelParameter {
  const char* name;
  double PixelModel::* field;
  double lo, hi;
};
std::span<const PixelParameter> pixel_parameters();

/// Applies a pixel setting by name: "ideal" (leaves the spec as it is), "dvs"
/// (dvs_pixel_normal + its background rate), "dvs-dim". False for an unknown name.
bool apply_pixel_setting(SceneSpec& spec, std::string_view name);

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
  std::int64_t early_us_ = 0;     // how far before its slice an event can be stamped
  std::vector<std::uint32_t> hot_pixels_;  // pixel indices y * width + x (pixel model)
  std::size_t ready_ = 0;         // pending_[0, ready_) can no longer be preceded
  std::size_t emitted_ = 0;       // pending_[0, emitted_) were handed out
};

}  // namespace evlife::io
