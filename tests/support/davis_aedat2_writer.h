// Test-only writer of jAER AEDAT 2.0 files from DAVIS cameras (no such file
// is shared). It packs addresses as jAER's own USB code does (the
// DAViS FX2/FX3 hardware interfaces and IMUSample, github.com/SensorsINI/jaer):
// a DVS event at sensor column c, row r (row 0 at the top, as libcaer) gets
// raw x = W-1 - c, raw y = H-1 - r; it shares no code with evlife's reader.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace evlife::test {

class DavisAedat2Writer {
 public:
  /// Header: magic, the jAER comment lines, `# HardwareInterface: DAVIS ...`
  /// and `# AEChip: <aechip_class>` (no AEChip line when it is empty).
  DavisAedat2Writer(const std::string& aechip_class, int width, int height);

  /// A DVS event at column x, row y (top-left origin).
  void dvs(int x, int y, bool on, std::uint32_t t_us);
  /// An APS ADC sample: jAER address fields as they are (x, y unflipped).
  void aps(int x, int y, int read_cycle, int adc, std::uint32_t t_us);
  /// One IMU sample: 7 words (ax, ay, az, temperature, gx, gy, gz).
  void imu(const std::array<std::int16_t, 7>& values, std::uint32_t t_us);
  /// An external input event (a trigger on the sync connector).
  void external(std::uint32_t t_us);
  /// Any address, as given.
  void raw(std::uint32_t address, std::uint32_t t_us);

  const std::vector<char>& bytes() const { return bytes_; }
  /// File offset of the record written next.
  std::size_t size() const { return bytes_.size(); }

 private:
  int width_;
  int height_;
  std::vector<char> bytes_;
};

}  // namespace evlife::test
