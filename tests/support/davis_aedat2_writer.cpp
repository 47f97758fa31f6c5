#include "davis_aedat2_writer.h"

namespace evlife::test {

DavisAedat2Writer::DavisAedat2Writer(const std::string& aechip_class, int width, int height)
    : width_(width), height_(height) {
  std::string header =
      "#!AER-DAT2.0\r\n"
      "# This is a raw AE data file - do not edit\r\n"
      "# Data format is int32 address, int32 timestamp (8 bytes total), repeated for each event\r\n"
      "# Timestamps tick is 1 us\r\n"
      "# HardwareInterface: DAVIS FX3 0002-INI\r\n";
  if (!aechip_class.empty()) header += "# AEChip: " + aechip_class + "\r\n";
  bytes_.assign(header.begin(), header.end());
}

void DavisAedat2Writer::raw(std::uint32_t address, std::uint32_t t_us) {
  for (const std::uint32_t word : {address, t_us})
    for (int shift = 24; shift >= 0; shift -= 8) bytes_.push_back(static_cast<char>((word >> shift) & 0xFF));
}

void DavisAedat2Writer::dvs(int x, int y, bool on, std::uint32_t t_us) {
  const auto raw_x = static_cast<std::uint32_t>(width_ - 1 - x);
  const auto raw_y = static_cast<std::uint32_t>(height_ - 1 - y);
  raw((raw_y << 22) | (raw_x << 12) | ((on ? 1u : 0u) << 11), t_us);
}

void DavisAedat2Writer::aps(int x, int y, int read_cycle, int adc, std::uint32_t t_us) {
  raw(0x80000000u | (static_cast<std::uint32_t>(y) << 22) | (static_cast<std::uint32_t>(x) << 12) |
          (static_cast<std::uint32_t>(read_cycle & 3) << 10) | static_cast<std::uint32_t>(adc & 0x3FF),
      t_us);
}

void DavisAedat2Writer::imu(const std::array<std::int16_t, 7>& values, std::uint32_t t_us) {
  for (std::uint32_t code = 0; code < 7; ++code)
    raw(0x80000C00u | (code << 28) | (std::uint32_t{static_cast<std::uint16_t>(values[code])} << 12), t_us);
}

void DavisAedat2Writer::external(std::uint32_t t_us) { raw(0x00000400u, t_us); }

}  // namespace evlife::test
