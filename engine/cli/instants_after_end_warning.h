// The warning of `render --at` and `run --at` when instants asked for lie
// after the recording's last event: their frames show nothing new (the
// instants count from the first event; seconds given for a clock time, or
// milliseconds written as seconds, land there).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>

#include "evlife/algo/event.h"

namespace evlife::cli {

inline void warn_instants_after_end(const char* command, std::size_t count, std::int64_t first_t_us,
                                    std::int64_t last_t_us) {
  if (count == 0) return;
  std::fprintf(stderr,
               "evlife %s: warning: %zu of the --at instants lie after the last event "
               "(the recording is %.6f s long; --at takes seconds from the first event, or "
               "a unit: 500ms, 20us)\n",
               command, count, seconds_between(first_t_us, last_t_us));
}

}  // namespace evlife::cli
