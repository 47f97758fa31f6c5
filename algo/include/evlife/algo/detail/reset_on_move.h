// A value that a move leaves as T{}: what lets a class keep its implicit
// (defaulted) moves and still leave its moved-from object safe to call.
// LifetimeEstimator and ActiveEventMap bound every event by one: moved
// from, their sensor is 0 x 0, so process() labels every event noise
// (out_of_sensor) and feed() counts it out of the sensor, instead of
// indexing the per-pixel planes the move took away.
#pragma once

#include <utility>

namespace evlife::detail {

template <class T>
struct ResetOnMove {
  T value{};

  ResetOnMove() = default;
  explicit ResetOnMove(T v) noexcept : value(v) {}
  ResetOnMove(const ResetOnMove&) = default;
  ResetOnMove& operator=(const ResetOnMove&) = default;
  ResetOnMove(ResetOnMove&& other) noexcept : value(std::exchange(other.value, T{})) {}
  ResetOnMove& operator=(ResetOnMove&& other) noexcept {
    // A self-move (`x = std::move(x)`) empties the vectors beside it
    // (libstdc++), so the value resets with them: it kept the sensor size,
    // and the next call read the empty planes.
    value = this == &other ? T{} : std::exchange(other.value, T{});
    return *this;
  }
  ~ResetOnMove() = default;
};

}  // namespace evlife::detail
