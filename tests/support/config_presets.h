// The presets of config/ as options, for the tests that run the estimator
// with them (the files' content is checked against these by test_config's
// Config.*Preset* tests, so the values are tied to the files).
#pragma once

#include "evlife/algo/lifetime_options.h"

namespace evlife::test {

/// config/dim-light.yaml: lifetimes at least two standard errors from zero,
/// with the offset check.
inline LifetimeOptions dim_light_preset() {
  LifetimeOptions o;
  o.max_lifetime_standard_error = 0.5;
  o.max_event_offset_tolerances = 2.0;
  o.late_event_keeps_arrival_timing_noise = 15.0;
  o.late_follower_upstream_durations = 1.5;
  return o;
}

/// config/faint-texture.yaml: a +-0.4 lifetime band with the offset check,
/// fresh regions within 5 ms.
inline LifetimeOptions faint_texture_preset() {
  LifetimeOptions o;
  o.inlier_tolerance_lifetime_fraction = 0.4;
  o.max_event_offset_tolerances = 2.0;
  o.fresh_region_span_us = 5000.0;
  return o;
}

}  // namespace evlife::test
