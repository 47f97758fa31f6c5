// Options of the lifetime estimator (paper Section III). A plain struct with
// defaults; validate it with validate_lifetime_options() or by constructing a
// LifetimeEstimator, which throws std::invalid_argument naming the field.
#pragma once

#include <cstdint>
#include <string>

#include "evlife/algo/event.h"
#include "evlife/algo/option_info.h"

namespace evlife {

struct LifetimeOptions {
  /// Sensor size in pixels. 1..kMaxSensorSide each way.
  SensorSize sensor{128, 128};

  /// N: side of the square window around the new event, odd, 3..15.
  /// Larger N: more support, smoother velocity, more cost (O(N^2)).
  int window_size = 5;

  /// epsilon: expected share of outliers among the window's newer half.
  /// Sets the RANSAC iteration count (for ransac_confidence) and the minimum
  /// support m = (1 - epsilon) * N^2 / 2 (paper eq. 8; near the border, where
  /// only part of the window exists, halfway between that and the clipped
  /// window's value). In (0, 0.9].
  double outlier_fraction = 0.4;

  /// A region where some of the window's pixels have never fired (an edge
  /// entering a part of the sensor that has been dark since the start; a
  /// sensor whose pixels fire sparsely) cannot give eq. 8's m: only the
  /// pixels that fired can support a plane. There the pixels that never fired
  /// count as outside the window (the border rule: m halfway between the
  /// pixels that fired, the new event's included, and the full window), if
  /// every supporter fired within this span before the event and the event's
  /// own pixel did not (its later events are a burst's, not the edge
  /// entering): an entering edge's supporters lie within about 2 lifetimes,
  /// while background
  /// activity of R Hz/px brings N^2 x R x span events into the window in that
  /// time (0.5 at 20 ms, 5 x 5 and 1 Hz/px, the top of room-temperature DVS
  /// background activity and the pixel model's dim light), and a plane
  /// through a few of them must not pass. Longer spans label more of a
  /// recording's first passage but pass more noise (algo/README.md,
  /// *Warm-up*). Microseconds, [0, 1e6]; 0 = eq. 8 everywhere (the output
  /// before it).
  double fresh_region_span_us = 20000.0;

  /// Minimum support, in past events, of an event that continues an edge:
  /// one that the plane of an edge estimated at a neighbour upstream predicts
  /// within the inlier tolerance. Real pixels fire sparsely (a pixel whose
  /// threshold is not reached by an edge's contrast stays silent), so eq. 8's
  /// m, meant for a full window, starts edges and this one follows them.
  /// 2..(N^2-1)/2; 0 = eq. 8 for every event (the paper).
  int continuation_min_support = 3;

  /// Probability that RANSAC draws at least one all-inlier sample. (0, 1).
  double ransac_confidence = 0.99;

  /// Inlier tolerance, in time: a past event supports a candidate plane when
  /// its timestamp is within
  ///   max(inlier_tolerance_us, inlier_tolerance_lifetime_fraction * tau_c)
  /// of the plane's time at its pixel, tau_c being the candidate's lifetime.
  /// The floor (microseconds, (0, 1e6]) covers the sensor's timestamp jitter;
  /// the fraction ((0, 0.5]) covers timing noise that grows with the lifetime
  /// (slow edges fire late and loosely). Above about a third of the lifetime,
  /// stale events fit steep planes through a noise event and noise passes as
  /// an edge (above 0.35, stale samples of one time on two neighbouring
  /// diagonals of the window fit a steep plane through it);
  /// config/faint-texture.yaml takes 0.4 with max_event_offset_tolerances,
  /// which rejects those planes, for scenes with little background activity.
  double inlier_tolerance_us = 60.0;
  double inlier_tolerance_lifetime_fraction = 0.3;
  /// The floor adapts to the timing noise actually observed: it is at least
  /// this factor x the window's median residual RMS (us) of the last accepted
  /// fits (median over its columns of each column's median, a pixel without a
  /// fit counting 0: algo/src/window_noise.h; a mean let fits through
  /// background activity widen the floor until noise passed). Latency jitter
  /// grows from ~50 us in bright light to several hundred us in dim light; a
  /// fixed floor either rejects dim edges or passes noise in bright light.
  /// In [0, 10]; 0 = the fixed floor alone.
  double inlier_tolerance_residual_factor = 2.0;

  /// After the plane fit, the lifetime is fitted again along its direction
  /// without the samples causality censors: those the plane puts after the
  /// new event or less than censoring_noise_factor x the observed timing noise
  /// (the window's median residual RMS of the last fits, as above) before it. Of the
  /// pixels the edge reaches about now, only those whose latency jitter was
  /// early have fired; they pull the plane flat and the lifetime short (dim
  /// light, lifetimes below 500 us: median -24 %). No effect where no timing
  /// noise was observed. false = the plane fit's lifetime (the paper). Factor
  /// in [0, 10].
  bool skip_censored_samples = true;
  double censoring_noise_factor = 1.0;

  /// Regularize the least-squares plane towards the plane predicted for this
  /// pixel by an earlier event (paper eq. 12).
  bool regularization = true;

  /// lambda(dt_err) = lambda_offset + lambda_gain * exp(-lambda_decay_per_us * dt_err)
  /// (paper eq. 13, dt_err = |t - t_hat| in microseconds). The refit minimizes
  ///   sum_i (dt_i - c - g . dp_i)^2 + lambda_unit_px2 * lambda(dt_err) * |g - g_hat|^2
  /// with g the SAE gradient in us/px: lambda_unit_px2 converts the paper's
  /// dimensionless weight into our units (px^2 of data spread it is worth).
  /// 0.3 was chosen by measurement: with 1.0 the prior outweighs a 5 x 5
  /// window's data and biases curved motion (a rotating bar) by ~3 deg; 0.1
  /// lets the bursts' timing noise through on real pixels.
  /// lambda_decay_per_us: the paper's 0.005 treats a prediction 200 us off as
  /// poor, but in dim light 200-800 us is the pixels' own latency jitter, and
  /// every prior was discarded (dim rotating bar p90 33 %); 0.002 fades the
  /// weight over 500 us: dim bar 28 %, normal light within 1 point.
  double lambda_offset = 9.0;
  double lambda_gain = 100.0;
  double lambda_decay_per_us = 0.002;
  double lambda_unit_px2 = 0.3;

  /// Bursts (real DVS pixels fire several events per edge crossing, one per
  /// threshold multiple, spread over the edge's ramp): an event at a pixel
  /// less than burst_window_lifetimes x the burst's lifetime after the burst's
  /// latest event, and less than burst_span_lifetimes x it after the burst's
  /// first, is a follower. It keeps the arrival time (the first event of the
  /// burst) in the surface and inherits the burst's estimate. 0 = every event
  /// is an arrival (the paper's last-event surface). In [0, 10].
  double burst_window_lifetimes = 2.0;

  /// A burst lasts as long as its edge's ramp takes to cross the pixel (blur
  /// x lifetime: 1.5-2.5 lifetimes where optics spread an edge over 1.5-2.5
  /// px) plus the latency jitter. Followers chain, each within
  /// burst_window_lifetimes of the burst's latest event, up to this many
  /// lifetimes after its arrival: a burst that goes on firing keeps its
  /// followers, a single event chains nothing. In the pixel model with a 2.5
  /// px blur 5 % of the edge events come more than 2 lifetimes after their
  /// burst's first; on stripes.mat 1.6 % of the events are such followers
  /// (bench/real_data_figures.py). <= burst_window_lifetimes: followers
  /// only within burst_window_lifetimes of the arrival (the rule before).
  /// In [0, 20].
  double burst_span_lifetimes = 4.0;

  /// A threshold crossing fires about C / theta events (contrast over
  /// threshold: 1-4 in the and the pixel model's range, ~19 for a
  /// black-on-white print at theta 0.15), while a hot pixel fires at its own
  /// rate, up to kHz on real sensors (sample.aedat4's DVXplorer: pixels at
  /// 0.2-1.1 kHz all through the recording). Within a burst's span such a
  /// pixel fired dozens of events, which passed as its followers. So past this
  /// many followers an event is judged on its own, unless a neighbour
  /// upstream holds a burst with as many (the edge's bursts are that long
  /// everywhere: a low threshold). Pixel model with 1e-3 of the pixels hot at
  /// 1 kHz: noise labelled noise 95.8 -> 97.1 % (normal), 96.8 -> 97.4 % (dim);
  /// sample.aedat4's pixels at >= 200 Hz 10.6 -> 4.0 % with a lifetime; the
  /// settings' scenes within 0.01 point, the other recordings within 0.03
  /// (algo/README.md, *Hot pixels*). 0 = no limit (the rule before). In [0, 255].
  int max_burst_followers = 16;

  /// A burst lasts as long as the pixel's response takes, too: a photoreceptor
  /// of limited bandwidth (dim light: 10-300 Hz, a time constant of 0.5-16 ms)
  /// approaches each edge exponentially, and its threshold crossings follow
  /// over about that time constant however fast the edge, many lifetimes of
  /// a fast edge. The same slow response spreads the edge's arrivals at
  /// neighbouring pixels, which the fit's residual RMS measures (~a sixth of
  /// the time constant). So where this many x the residual RMS of a burst's
  /// fit exceeds burst_span_lifetimes, an event is a follower also up to that
  /// time after the burst's arrival, as long as no pixel upstream (where the
  /// edge came from) has had a newer arrival since (by more than twice that
  /// RMS and the tolerance floor): a new edge reaches them first. Without it,
  /// the late events of such bursts overwrote their arrivals in the surface
  /// and every fit downstream came out short (30 Hz photoreceptor, lifetimes
  /// 2-5 ms: median -29 %; -25 % at 10). Off by default: background activity
  /// after an edge then passes as its follower (dim light: noise labelled
  /// noise 97.9 -> 97.6 % at 10, faint texture 96.7 -> 96.3 %; algo/README.md,
  /// A photoreceptor of limited bandwidth). 0 = off. In [0, 100].
  double burst_span_timing_noise = 0.0;

  /// Shading: an edge spread over B px (a soft or defocused edge, a
  /// luminance gradient) crosses a pixel in B lifetimes, and the pixel fires
  /// once per threshold theta of the ramp's contrast C, every B x theta / C
  /// lifetimes (2 at B = 5 px, theta = 0.2, C = 0.5). Those events come past
  /// the follower window and the burst span; taken for new arrivals they
  /// overwrote the arrival in the surface, and the fits downstream, which
  /// saw the pixel reached late, came out flat (5 px: lifetimes a median
  /// 34 % short, median error 36 %). Such an event is still a follower up to this many
  /// lifetimes after its burst's arrival while the ramp is seen passing: a
  /// neighbour upstream (where the edge came from) holds an estimated burst
  /// that arrived before this one (the same edge, not a new one) and has
  /// fired since this pixel's latest event, within
  /// ramp_follower_upstream_lifetimes of now. After a sharp edge the upstream
  /// burst ends before this pixel's, so background activity there stays
  /// noise. 0 = off (the output before it). In [0, 20].
  double ramp_follower_span_lifetimes = 6.0;

  /// How recently (in the burst's lifetimes) the upstream neighbour must
  /// have fired for the ramp to count as passing (ramp_follower_span_lifetimes).
  /// At 2 (the follower window) more of a 5 px ramp's events are followers,
  /// but faint texture's noise falls below 97 % with config/faint-texture.yaml.
  /// In (0, 10].
  double ramp_follower_upstream_lifetimes = 1.5;

  /// A photoreceptor of limited bandwidth (dim light) fires a burst's later
  /// events a time constant T or two after its first, many lifetimes of a
  /// fast edge and past the follower window; taken for new arrivals, they
  /// overwrote the arrival in the surface, the pixel looked reached late and
  /// the fits downstream came out flat. An event (with a fit of its own or
  /// labelled noise) within this many x the window's observed timing noise
  /// (its median residual RMS of the last fits, which grows with T) of its
  /// pixel's last arrival leaves that arrival in the surface: the surface
  /// holds each burst's first event. An event with a fit keeps its lifetime
  /// and its burst is its own, anchored at the arrival. 0 = off (the output
  /// before, bit for bit). In [0, 100].
  double late_event_keeps_arrival_timing_noise = 0.0;

  /// Such a late event that no fit supports, at a pixel whose burst has an
  /// estimate, is the burst's follower where it comes within this many x the
  /// duration (latest event after arrival) of an upstream neighbour's
  /// estimated burst of the same edge (arrived before this pixel's): the
  /// neighbours' own bursts show how long the pixels' response lasts. Not
  /// while an upstream neighbour holds an arrival newer than this pixel's (a
  /// new edge reaches them first). 0 = off. In [0, 100].
  double late_follower_upstream_durations = 0.0;

  /// A prediction (paper III-B.2) is for the edge that made it: if the
  /// predicted pixel's next event comes more than this many of the predicted
  /// lifetimes early or late (at least inlier_tolerance_us), the edge passed
  /// without firing there (a pixel that missed its threshold) and the event
  /// belongs to another edge: it gets no prediction and no prior. 0 = a
  /// prediction waits for the next event however late (the paper). In [0, 100].
  double prediction_expiry_lifetimes = 2.0;

  /// Lifetimes below inlier_tolerance_us / (window_size / 2) are treated as
  /// noise: a plane that rises less than the timestamp jitter across the
  /// window's half-width is not resolved by the timestamps (a blob whose
  /// pixels fire within a few us, a readout that stamps a row with one time).
  /// Lifetimes above this are treated as noise: a plane this steep cannot be
  /// told from background activity. Its tolerance band (+-0.3 lifetime) holds
  /// a pixel's noise event with probability ~0.6 x lifetime x rate: 0.18 at
  /// 0.3 s and 1 Hz/px (the top of room-temperature DVS background activity),
  /// so half a window of supporters comes by chance. With 1 s, a static scene
  /// under 1 Hz/px passed 3-5 % of its noise once every pixel had fired
  /// (tests/test_long_recordings.cpp); with 0.3 s, 0.1 %. Edges slower than
  /// 3.3 px/s are labelled noise. Microseconds, (0, 1e9].
  double max_lifetime_us = 3.0e5;

  /// The plane of the inliers alone (the least-squares plane with its own
  /// offset, the new event left out, the prior as in the refit) must pass
  /// within this many inlier tolerances of the new event (or of the arrival
  /// of the burst it follows), else the event is labelled noise. RANSAC's
  /// planes pass through the new event by construction; where the samples
  /// only fit such a plane within the tolerance band (stale samples of one
  /// time on two diagonals around a noise event), their own plane misses the
  /// event by about their age. With the default tolerance it costs share
  /// (garfield.mat 0.80 -> 0.76) for less noise; config/faint-texture.yaml
  /// pairs 2 with a wider tolerance. 0 = no check (the default). In [0, 100].
  double max_event_offset_tolerances = 0.0;

  /// The same check for continuations alone (events with less support than
  /// eq. 8's, accepted because an edge upstream predicts them), which have
  /// few samples and a wide band where the upstream plane is steep: there a
  /// plane through stale and noise samples passes the band of its own long
  /// lifetime and the predictions carry it on. 6 tolerances of the default
  /// band (+-0.3 lifetimes) are 1.8 lifetimes: beyond the spread of a burst's
  /// first event over an edge blurred across 1.5 px, which a real edge's
  /// continuation may have. Where both are set, the smaller applies. 0 = off
  /// (the output before it). In [0, 100].
  double continuation_max_event_offset_tolerances = 6.0;

  /// Lifetimes whose standard error (from the fit's own residuals and the
  /// samples' spread along the motion) exceeds this share of the lifetime are
  /// not resolved by the timestamps and treated as noise: in dim light the
  /// latency jitter (hundreds of us) approaches the lifetime of fast edges.
  /// At 1 (the default) a lifetime as uncertain as itself carries no
  /// information; config/dim-light.yaml sets 0.5 (a lifetime two standard
  /// errors from zero), which also rejects more of the real recordings' fits
  /// (see README). 0 = no check. In [0, 10].
  double max_lifetime_standard_error = 1.0;

  /// Seed of the RANSAC sampler. Each event draws from a generator seeded by
  /// (seed, x, y, t, p), so results do not depend on processing order.
  std::uint64_t seed = 0x5eed;
};

/// The one declaration of every option's key, range and documentation (see
/// option_info.h): calls f(info, accessor) per field, `accessor(o)` returning
/// the field of a LifetimeOptions (const or not). validate_lifetime_options(),
/// the `estimator:` keys of config/ and the --help texts read it.
template <typename F>
void for_each_lifetime_option(F&& f) {
  f(OptionInfo{"sensor.width", "", 1, kMaxSensorSide, false, false, false, false,
               "sensor width, px (input formats that state it win)"}, [](auto& o) -> auto& { return o.sensor.width; });
  f(OptionInfo{"sensor.height", "", 1, kMaxSensorSide, false, false, false, false, "sensor height, px"},
    [](auto& o) -> auto& { return o.sensor.height; });
  f(OptionInfo{"window_size", "window-size", 3, 15, false, false, true, false,
               "N: side of the square window around each event"}, [](auto& o) -> auto& { return o.window_size; });
  f(OptionInfo{"outlier_fraction", "", 0.0, 0.9, true, false, false, false,
               "epsilon: expected share of outliers (RANSAC, minimum support)"},
    [](auto& o) -> auto& { return o.outlier_fraction; });
  f(OptionInfo{"ransac_confidence", "", 0.0, 1.0, true, true, false, false,
               "probability that RANSAC draws an all-inlier sample"},
    [](auto& o) -> auto& { return o.ransac_confidence; });
  f(OptionInfo{"inlier_tolerance_us", "", 0.0, 1e6, true, false, false, false,
               "inlier tolerance floor, us"}, [](auto& o) -> auto& { return o.inlier_tolerance_us; });
  f(OptionInfo{"inlier_tolerance_lifetime_fraction", "", 0.0, 0.5, true, false, false, false,
               "inlier tolerance as a share of the candidate's lifetime"},
    [](auto& o) -> auto& { return o.inlier_tolerance_lifetime_fraction; });
  f(OptionInfo{"inlier_tolerance_residual_factor", "", 0.0, 10.0, false, false, false, false,
               "floor >= this x the window's median residual RMS of recent fits; 0 = fixed floor"},
    [](auto& o) -> auto& { return o.inlier_tolerance_residual_factor; });
  f(OptionInfo{"skip_censored_samples", "", 0, 1, false, false, false, false,
               "refit the lifetime without the samples causality censors"},
    [](auto& o) -> auto& { return o.skip_censored_samples; });
  f(OptionInfo{"censoring_noise_factor", "", 0.0, 10.0, false, false, false, false,
               "censored: the plane puts them < this x the timing noise before the event"},
    [](auto& o) -> auto& { return o.censoring_noise_factor; });
  f(OptionInfo{"regularization", "", 0, 1, false, false, false, false,
               "regularize the refit towards the predicted plane (eq. 12)"},
    [](auto& o) -> auto& { return o.regularization; });
  f(OptionInfo{"lambda_offset", "", 0.0, 1e9, false, false, false, false, "eq. 13 offset"},
    [](auto& o) -> auto& { return o.lambda_offset; });
  f(OptionInfo{"lambda_gain", "", 0.0, 1e9, false, false, false, false, "eq. 13 gain"},
    [](auto& o) -> auto& { return o.lambda_gain; });
  f(OptionInfo{"lambda_decay_per_us", "", 0.0, 1e3, false, false, false, false,
               "eq. 13 decay, 1/us"}, [](auto& o) -> auto& { return o.lambda_decay_per_us; });
  f(OptionInfo{"lambda_unit_px2", "", 0.0, 1e6, false, false, false, false,
               "weight of the prior in px^2 of data spread"}, [](auto& o) -> auto& { return o.lambda_unit_px2; });
  f(OptionInfo{"fresh_region_span_us", "", 0.0, 1e6, false, false, false, false,
               "never-fired pixels count as outside the window if the supporters fired within this span, us; 0 = off"},
    [](auto& o) -> auto& { return o.fresh_region_span_us; });
  f(OptionInfo{"continuation_min_support", "", 0, 112, false, false, false, false,
               "minimum support of an edge's continuation: 0 or 2..(N^2-1)/2"},
    [](auto& o) -> auto& { return o.continuation_min_support; });
  f(OptionInfo{"burst_window_lifetimes", "", 0.0, 10.0, false, false, false, false,
               "burst followers within this many lifetimes; 0 = none"},
    [](auto& o) -> auto& { return o.burst_window_lifetimes; });
  f(OptionInfo{"burst_span_lifetimes", "", 0.0, 20.0, false, false, false, false,
               "chained followers at most this many lifetimes after the arrival"},
    [](auto& o) -> auto& { return o.burst_span_lifetimes; });
  f(OptionInfo{"max_burst_followers", "", 0, 255, false, false, false, false,
               "followers a burst may have at most (a hot pixel fires on); 0 = no limit"},
    [](auto& o) -> auto& { return o.max_burst_followers; });
  f(OptionInfo{"burst_span_timing_noise", "", 0.0, 100.0, false, false, false, false,
               "followers also up to this many x the burst fit's residual RMS, none newer upstream; 0 = off"},
    [](auto& o) -> auto& { return o.burst_span_timing_noise; });
  f(OptionInfo{"ramp_follower_span_lifetimes", "", 0.0, 20.0, false, false, false, false,
               "followers on a passing shading ramp up to this many lifetimes after the arrival; 0 = off"},
    [](auto& o) -> auto& { return o.ramp_follower_span_lifetimes; });
  f(OptionInfo{"ramp_follower_upstream_lifetimes", "", 0.0, 10.0, true, false, false, false,
               "the ramp passes while an upstream neighbour fired within this many lifetimes"},
    [](auto& o) -> auto& { return o.ramp_follower_upstream_lifetimes; });
  f(OptionInfo{"late_event_keeps_arrival_timing_noise", "", 0.0, 100.0, false, false, false, false,
               "an event within this many x the window's timing noise of its pixel's arrival leaves it; 0 = off"},
    [](auto& o) -> auto& { return o.late_event_keeps_arrival_timing_noise; });
  f(OptionInfo{"late_follower_upstream_durations", "", 0.0, 100.0, false, false, false, false,
               "an unsupported event within this many x an upstream burst's duration follows its burst; 0 = off"},
    [](auto& o) -> auto& { return o.late_follower_upstream_durations; });
  f(OptionInfo{"prediction_expiry_lifetimes", "", 0.0, 100.0, false, false, false, false,
               "a prediction missed by more lifetimes is void; 0 = never"},
    [](auto& o) -> auto& { return o.prediction_expiry_lifetimes; });
  f(OptionInfo{"max_lifetime_us", "", 0.0, 1e9, true, false, false, false,
               "longer lifetimes are noise, us"}, [](auto& o) -> auto& { return o.max_lifetime_us; });
  f(OptionInfo{"max_event_offset_tolerances", "", 0.0, 100.0, false, false, false, false,
               "noise when the inliers' own plane misses the event by more tolerances; 0 = off"},
    [](auto& o) -> auto& { return o.max_event_offset_tolerances; });
  f(OptionInfo{"continuation_max_event_offset_tolerances", "", 0.0, 100.0, false, false, false, false,
               "the same for continuations alone (the smaller applies); 0 = off"},
    [](auto& o) -> auto& { return o.continuation_max_event_offset_tolerances; });
  f(OptionInfo{"max_lifetime_standard_error", "", 0.0, 10.0, false, false, false, false,
               "noise when the lifetime's standard error exceeds this share of it; 0 = off"},
    [](auto& o) -> auto& { return o.max_lifetime_standard_error; });
  f(OptionInfo{"seed", "", 0.0, 18446744073709551615.0, false, false, false, false,
               "seed of the RANSAC sampler"}, [](auto& o) -> auto& { return o.seed; });
}

/// Returns an empty string when the options are usable, else a message that
/// names the offending field and its allowed range. Never throws.
std::string validate_lifetime_options(const LifetimeOptions& options);

}  // namespace evlife
