// The DVS pixel model of the synthetic scenes (PixelModel in synthetic_scene.h):
// the burst of events one edge crossing gives at a pixel, the fixed-pattern
// threshold mismatch, the hot pixels. Stateless: every draw is a hash of the
// crossing's identity, so a burst does not depend on how the scene is sliced.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "evlife/io/synthetic_scene.h"

namespace evlife::io::detail {

/// Most events one crossing can give (validate_scene_spec bounds contrast /
/// threshold so that a burst never reaches it).
inline constexpr std::size_t kMaxBurstEvents = 64;

/// An edge ramp never lasts longer than this (us): near a rotation centre the
/// lifetime diverges (no lifetime is scored there), and the reader must hold
/// back half a ramp of events, so the ramp is capped to bound its memory.
inline constexpr double kMaxEdgeRampUs = 100'000.0;

/// One crossing of a pixel centre by an edge centre.
struct Crossing {
  double t_c_us = 0.0;        ///< when the edge centre crosses the pixel centre
  double lifetime_us = 0.0;   ///< true lifetime there
  int x = 0;
  int y = 0;
  int p = 1;                  ///< +1 ON, -1 OFF
  int feature = 0;
  long long index = 0;        ///< which crossing of this feature's edge (k of the generator)
  /// The edge moves only within [t_from, t_to): before, the pixel has adapted
  /// to the still scene (its reference sits at that level minus the residual);
  /// after, the level stays.
  double t_from_us = 0.0;
  double t_to_us = std::numeric_limits<double>::infinity();
};

/// Timestamps (not rounded) of a crossing's burst, in firing order.
struct Burst {
  std::array<double, kMaxBurstEvents> t_us{};
  std::size_t count = 0;
};

class PixelSampler {
 public:
  PixelSampler(const PixelModel& model, std::uint64_t seed) : m_(model), seed_(seed) {}

  /// Log-intensity step of a feature's edges (ln units).
  double contrast(int feature) const;
  /// Threshold of a pixel for one polarity (ln units), fixed pattern.
  double threshold(int x, int y, int p) const;
  /// Duration of the edge's log-intensity ramp at a pixel (us).
  double ramp_us(double lifetime_us) const;
  /// The events of one crossing (see PixelModel).
  void burst(const Crossing& c, Burst& out) const;
  /// A time (us) as the readout stamps it: floored to the timestamp quantum.
  double stamp_us(double t_us) const;
  /// The hot pixels (indices y * width + x), sorted, without repeats.
  std::vector<std::uint32_t> hot_pixels(SensorSize sensor) const;
  /// A pixel latency (us): mean and jitter of the model, Gaussian truncated
  /// at 4 sigma and at 0, drawn from `key`.
  double latency_us(std::uint64_t key) const;

 private:

  PixelModel m_;
  std::uint64_t seed_;
};

/// How far before its crossing time an event of this scene can be stamped (us):
/// half the longest ramp (gratings: blur * tau; rotating bars: the largest tau
/// over the region's pixels, i.e. the shortest arm at the slowest rotation).
double max_early_offset_us(const SceneSpec& spec);

}  // namespace evlife::io::detail
