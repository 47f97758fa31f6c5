// Private: the jAER chip classes whose AEDAT 2.0 files evlife reads — the
// `# AEChip: <java class>` header line selects the address layout and the
// sensor size. One table (aedat2_chips.cpp); add a chip there.
#pragma once

#include <string>
#include <string_view>

namespace evlife::io::detail {

enum class Aedat2Layout {
  dvs128,  // 16-bit address: bit 15 external, y 8-14, x 1-7, polarity bit 0
  davis,   // 32-bit address: bit 31 APS/IMU, y 22-30, x 12-21, polarity 11, external 10
};

struct Aedat2Chip {
  std::string_view class_prefix;  // simple class name (after the last '.'), case-insensitive prefix
  Aedat2Layout layout;
  int width;
  int height;
};

/// The chip of an AEChip value ("eu.seebetter.ini.chips.davis.DAVIS240C");
/// nullptr when it is not in the table.
const Aedat2Chip* find_aedat2_chip(std::string_view aechip_class);

/// The DVS128, assumed when a file has no AEChip line (jAER before 2014).
const Aedat2Chip& default_aedat2_chip();

/// "DVS128, Tmpdiff128, DAVIS240..., ..." for error messages.
std::string known_aedat2_chips();

}  // namespace evlife::io::detail
