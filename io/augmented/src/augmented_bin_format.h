// Private: layout of the evlife binary augmented event format (.bin), shared
// by its writer and reader. Specification: README, "Binary augmented event
// format" (all little-endian):
//   header (32 B): magic "EVLIFEAE" | u16 version = 1 | u16 header_bytes = 32 |
//     u16 record_bytes = 32 | u16 flags = 0 | u32 sensor width | u32 sensor
//     height | 8 reserved zero bytes
//   record (32 B): i64 t_us | u16 x | u16 y | i8 p (+1/-1) | 3 zero bytes |
//     f32 lifetime_us | f32 vx_px_s | f32 vy_px_s | f32 prediction_error_us (NaN = none)
// Readers accept larger header_bytes / record_bytes from later versions
// (which append fields) and use the leading fields they know; a version-1
// header stating other sizes is refused as corrupt.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string_view>

#include "evlife/algo/event.h"
#include "evlife_bin_magic.h"

namespace evlife::io::detail::augmented_bin {

inline constexpr std::string_view kMagic = kAugmentedBinMagic;
inline constexpr std::uint16_t kVersion = 1;
inline constexpr std::size_t kHeaderBytes = 32;
inline constexpr std::size_t kRecordBytes = 32;

static_assert(std::endian::native == std::endian::little,
              "the .bin codec memcpy's little-endian fields: add byte swaps for this host");

template <class T>
void put(unsigned char* dst, std::size_t offset, T value) noexcept {
  std::memcpy(dst + offset, &value, sizeof(T));  // little-endian hosts only (checked at build)
}
template <class T>
T get(const unsigned char* src, std::size_t offset) noexcept {
  T value;
  std::memcpy(&value, src + offset, sizeof(T));
  return value;
}

inline void encode(const AugmentedEvent& a, unsigned char* r) noexcept {
  put<std::int64_t>(r, 0, a.event.t_us);
  put<std::uint16_t>(r, 8, a.event.x);
  put<std::uint16_t>(r, 10, a.event.y);
  put<std::int8_t>(r, 12, a.event.p);
  r[13] = r[14] = r[15] = 0;  // padding: zero for bit-exact files
  put<float>(r, 16, a.lifetime_us);
  put<float>(r, 20, a.vx_px_s);
  put<float>(r, 24, a.vy_px_s);
  put<float>(r, 28, a.prediction_error_us);
}

inline AugmentedEvent decode(const unsigned char* r) noexcept {
  AugmentedEvent a;
  a.event.t_us = get<std::int64_t>(r, 0);
  a.event.x = get<std::uint16_t>(r, 8);
  a.event.y = get<std::uint16_t>(r, 10);
  a.event.p = get<std::int8_t>(r, 12);
  a.lifetime_us = get<float>(r, 16);
  a.vx_px_s = get<float>(r, 20);
  a.vy_px_s = get<float>(r, 24);
  a.prediction_error_us = get<float>(r, 28);
  return a;
}

}  // namespace evlife::io::detail::augmented_bin
