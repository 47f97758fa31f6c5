// A value that a move leaves as T{}: what lets a class keep its implicit
// (defaulted) moves and still leave its moved-from object safe to call.
// LifetimeEstimator bounds every event by one: moved from, its sensor is
// 0 x 0, so process() labels every event noise (out_of_sensor) instead of
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
    value = std::exchange(other.value, T{});
    return *this;
  }
  ~ResetOnMove() = default;
};

}  // namespace evlife::detail
