// Chip classes of jAER (github.com/SensorsINI/jaer, src/eu/seebetter/ini/
// chips/davis/*.java and ch/unizh/ini/jaer/chip/retina/DVS128.java): sizes
// from each class's setSizeX/setSizeY. Every DAVIS class listed decodes with
// DavisBaseCamera.DavisEventExtractor and the DavisChip address constants.
// Left out on purpose: classes with an extractor of their own (CDAVIS,
// Davis208PixelParade, RGBW sensors) — refused with the list below.
#include "aedat2_chips.h"

#include <algorithm>
#include <array>
#include <cctype>

namespace evlife::io::detail {
namespace {

constexpr std::array kChips{
    Aedat2Chip{"DVS128", Aedat2Layout::dvs128, 128, 128},
    Aedat2Chip{"Tmpdiff128", Aedat2Layout::dvs128, 128, 128},
    Aedat2Chip{"DAVIS240", Aedat2Layout::davis, 240, 180},  // DAVIS240A/B/C, DAViS240
    Aedat2Chip{"SBret10", Aedat2Layout::davis, 240, 180},   // the DAVIS240A's first class name
    Aedat2Chip{"DVS240", Aedat2Layout::davis, 240, 180},
    Aedat2Chip{"Davis346", Aedat2Layout::davis, 346, 260},  // A/B/C, cBSI, mini, Zynq, ...
    Aedat2Chip{"Davis128", Aedat2Layout::davis, 128, 128},
    Aedat2Chip{"Davis640", Aedat2Layout::davis, 640, 480},
};

bool starts_with_nocase(std::string_view text, std::string_view prefix) {
  return text.size() >= prefix.size() &&
         std::equal(prefix.begin(), prefix.end(), text.begin(), [](char a, char b) {
           return std::tolower(static_cast<unsigned char>(a)) ==
                  std::tolower(static_cast<unsigned char>(b));
         });
}

}  // namespace

const Aedat2Chip* find_aedat2_chip(std::string_view aechip_class) {
  const auto first = aechip_class.find_first_not_of(" \t");
  if (first == std::string_view::npos) return nullptr;
  aechip_class.remove_prefix(first);
  while (!aechip_class.empty() && std::isspace(static_cast<unsigned char>(aechip_class.back())))
    aechip_class.remove_suffix(1);
  const auto dot = aechip_class.rfind('.');
  const std::string_view simple = dot == std::string_view::npos ? aechip_class : aechip_class.substr(dot + 1);
  for (const Aedat2Chip& chip : kChips)
    if (starts_with_nocase(simple, chip.class_prefix)) return &chip;
  return nullptr;
}

const Aedat2Chip& default_aedat2_chip() { return kChips[0]; }

std::string known_aedat2_chips() {
  std::string out;
  for (const Aedat2Chip& chip : kChips) {
    if (!out.empty()) out += ", ";
    out += chip.class_prefix;
    out += "* (" + std::to_string(chip.width) + "x" + std::to_string(chip.height) + ")";
  }
  return out;
}

}  // namespace evlife::io::detail
