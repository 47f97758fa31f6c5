// Private: how evlife's own binary output (.bin, io/augmented) begins, for
// the recording readers too: given to a command that reads recordings, or
// named .bin without it, the file is said to be what it is, not "an unknown
// format" followed by the list of every format.
#pragma once

#include <string>
#include <string_view>

#include "reader_registry.h"  // has_extension

namespace evlife::io::detail {

inline constexpr std::string_view kAugmentedBinMagic = "EVLIFEAE";

/// A path named like evlife's binary output (no other format evlife reads
/// uses .bin): its writer is chosen by it, and a file so named that no reader
/// takes is reported as a bad .bin.
inline bool named_like_augmented_bin(std::string_view path) { return has_extension(path, ".bin"); }

/// The reason a file named .bin whose first bytes are `head` is not evlife's.
inline std::string not_augmented_bin_reason(std::string_view head) {
  return "not evlife's .bin: it starts with '" + std::string(head.substr(0, kAugmentedBinMagic.size())) +
         "', evlife's .bin with '" + std::string(kAugmentedBinMagic) + "' (a corrupt file, or not evlife's)";
}

/// The reason evlife's .bin is not read as a recording (by the estimating commands).
inline constexpr std::string_view kAugmentedBinIsNoRecording =
    "evlife's output (.bin: its events carry lifetimes already): `evlife render`, `eval`, `info` and `convert` "
    "and Python's evlife.read_augmented read it; to estimate again, process the recording it came from";

}  // namespace evlife::io::detail
