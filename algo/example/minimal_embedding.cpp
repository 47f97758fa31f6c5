// The smallest flight-software integration: link evlife::algo only, build the
// estimator once at start-up, call process() per event from your own loop.
// Built by CMake as `evlife_embedding_example`; `ctest -R embedding` runs it.
#include <cstdio>
#include <string>

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

  // A vertical edge sweeping right at 2000 px/s: pixel x fires at t = x * 500 us.
  int with_lifetime = 0;
  for (int x = 0; x < 40; ++x) {
    for (int y = 0; y < 20; ++y) {
      const evlife::Event e{x * 500, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), +1};
      const evlife::AugmentedEvent a = estimator.process(e);  // noexcept, no allocation
      if (!a.is_noise()) ++with_lifetime;
      if (x == 30 && y == 10) {
        std::printf("event (30,10): lifetime %.1f us, velocity (%.0f, %.0f) px/s\n",
                    static_cast<double>(a.lifetime_us), static_cast<double>(a.vx_px_s),
                    static_cast<double>(a.vy_px_s));
      }
    }
  }
  std::printf("%d of 800 events got a lifetime\n", with_lifetime);
  return with_lifetime > 600 ? 0 : 1;
}
