// Random draws as hashes of what they are for (seed, feature, pixel, ...):
// a draw does not depend on the order things are generated in, and is the
// same on every platform (no std:: distributions).
#pragma once

#include <cmath>
#include <cstdint>
#include <numbers>

namespace evlife::io::detail {

// splitmix64's finalizer: identical on every platform, well mixed.
inline std::uint64_t mix(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

inline std::uint64_t combine(std::uint64_t h, std::uint64_t v) { return mix(h ^ mix(v)); }

template <typename... Rest>
std::uint64_t combine(std::uint64_t h, std::uint64_t v, Rest... rest) {
  return combine(combine(h, v), static_cast<std::uint64_t>(rest)...);
}

/// Uniform in [0, 1).
inline double uniform(std::uint64_t key) { return static_cast<double>(mix(key) >> 11) * 0x1.0p-53; }

/// Standard normal: Box-Muller from two independent hashes.
inline double gaussian(std::uint64_t key) {
  const double u1 = 1.0 - uniform(combine(key, 1));  // (0, 1]
  const double u2 = uniform(combine(key, 2));
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

}  // namespace evlife::io::detail
