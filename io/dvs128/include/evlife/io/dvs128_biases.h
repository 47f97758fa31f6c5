// The DVS128's 12 analog biases: what request 0xB8 sends (36 bytes, each bias
// 24-bit big endian, in the firmware's order below).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

namespace evlife::io {

struct Dvs128Biases {
  static constexpr int kCount = 12;
  /// Firmware order; also the keys of the bias file.
  static constexpr std::array<std::string_view, kCount> kNames = {
      "cas", "injGnd", "reqPd", "puX", "diffOff", "req",
      "refr", "puY", "diffOn", "diff", "foll", "pr"};
  static constexpr std::uint32_t kMax = 0xFFFFFF;  ///< 24 bits

  /// Default "fast" biases of libcaer and jAER.
  std::array<std::uint32_t, kCount> values = {1992,  1108364, 16777215, 8159221, 132, 309590,
                                              969,   16777215, 209996,  13125,   271, 217};

  /// The 36-byte data stage of request 0xB8.
  std::array<std::uint8_t, 3 * kCount> to_bytes() const noexcept;

  /// Reads a bias file: YAML with one `name: value` line per bias (names as
  /// in kNames, case-insensitive; values 0..16777215; '#' comments). Biases
  /// the file does not name keep their default. Throws std::runtime_error
  /// naming the file and line for a missing file, unknown name or bad value.
  static Dvs128Biases load_file(const std::string& path);
};

}  // namespace evlife::io
