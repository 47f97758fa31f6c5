// The smallest flight-software integration: link evlife::algo only, build the
// estimator and the active-event map once at start-up, call process() and
// feed() per event from your own loop, and read the sharp edge image as data.
// Built by CMake as `evlife_embedding_example`; `ctest -R embedding` runs it.
#include <cstdio>
#include <string>
#include <vector>

#include "evlife/algo/active_event_map.h"
#include "evlife/algo/lifetime_estimator.h"
#include "evlife/algo/make_lifetime_estimator.h"

int main() {
  evlife::LifetimeOptions options;  // paper defaults: N = 5, eps = 0.4, regularization on
  options.sensor = {240, 180};      // DAVIS240
  // Exception-free: builds with -fno-exceptions -fno-rtti (EVLIFE_ALGO_NO_EXCEPTIONS).
  evlife::LifetimeEstimatorOrError made = evlife::make_lifetime_estimator(options);
  if (!made) {
    std::fprintf(stderr, "bad options: %s\n", made.error.c_str());  // names the field
    return 1;
  }
  evlife::LifetimeEstimator& estimator = *made.estimator;  // all memory is allocated here
  // Which events are active now, with edge thinning (paper III-B.3); also
  // allocated once here. fits() is the exception-free check of the size.
  if (!evlife::ActiveEventMap::fits(options.sensor)) return 1;
  evlife::ActiveEventMap active(options.sensor);
  std::vector<evlife::ActivePixel> edge(256);  // room for the active pixels of one query

  // A vertical edge sweeping right at 2000 px/s: pixel x fires at t = x * 500 us.
  int with_lifetime = 0;
  for (int x = 0; x < 40; ++x) {
    for (int y = 0; y < 20; ++y) {
      const evlife::Event e{x * 500, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), +1};
      const evlife::AugmentedEvent a = estimator.process(e);  // noexcept, no allocation
      if (!a.is_noise()) ++with_lifetime;
      active.feed(a);  // noexcept, no allocation
      if (x == 30 && y == 10) {
        std::printf("event (30,10): lifetime %.1f us, velocity (%.0f, %.0f) px/s\n",
                    static_cast<double>(a.lifetime_us), static_cast<double>(a.vx_px_s),
                    static_cast<double>(a.vy_px_s));
      }
    }
  }
  std::printf("%d of 800 events got a lifetime\n", with_lifetime);

  // The edge image at t = 19.7 ms: the edge is at x = 39.4, so the active
  // events are the pixels of the last column(s) only: a sharp line, not the
  // 40-column smear of everything seen so far.
  const std::size_t n = active.active_pixels(19'700, edge);  // noexcept, no allocation
  int min_x = 1 << 30, max_x = -1;
  for (std::size_t i = 0; i < n && i < edge.size(); ++i) {
    min_x = edge[i].x < min_x ? edge[i].x : min_x;
    max_x = edge[i].x > max_x ? edge[i].x : max_x;
  }
  std::printf("active at t = 19.7 ms: %zu pixels in columns %d..%d\n", n, min_x, max_x);
  const bool sharp = n >= 20 && n <= 40 && min_x >= 38;
  return with_lifetime > 600 && sharp ? 0 : 1;
}
