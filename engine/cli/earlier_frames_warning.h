// The warning of `render -o DIR` and `run --frames DIR` when DIR held frames
// of an earlier run that this one did not replace: a video made of DIR's
// frame_*.png would mix the two runs (file names carry the time, so a
// shorter or differently paced run overwrites only some of them).
#pragma once

#include <cstddef>
#include <cstdio>
#include <string>

namespace evlife::cli {

inline void warn_earlier_frames(const char* command, const std::string& dir, std::size_t count) {
  if (count == 0) return;
  std::fprintf(stderr,
               "evlife %s: warning: %s also holds %zu frame_*.png of an earlier run that this one did not "
               "replace; empty the folder (or use a new one) before making a video of it\n",
               command, dir.c_str(), count);
}

}  // namespace evlife::cli
