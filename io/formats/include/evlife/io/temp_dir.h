// Where evlife puts its temporary files: the copy of a stream given as input,
// the decompressed copy of a file-compressed ROS 2 bag.
#pragma once

#include <string>

namespace evlife::io {

/// $TMPDIR, or /tmp where it is unset or empty.
std::string temp_dir();

}  // namespace evlife::io
