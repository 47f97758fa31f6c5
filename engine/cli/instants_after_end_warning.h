// The warning of `render --at` and `run --at` when instants asked for lie
// after the last event: their frames show nothing new (the instants count
// from the first event; seconds given for a clock time, or microseconds
// written as seconds, land there). `render` takes no --at with --from/--to:
// its span is the recording's; `run`'s is that of the events it read (a
// crop's, a synthetic scene's).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>

#include "evlife/algo/event.h"

namespace evlife::cli {

enum class InstantsOrigin { recording, events_read };

inline void warn_instants_after_end(const char* command, std::size_t count, std::int64_t first_t_us,
                                    std::int64_t last_t_us, InstantsOrigin origin) {
  if (count == 0) return;
  const bool read = origin == InstantsOrigin::events_read;
  std::fprintf(stderr,
               "evlife %s: warning: %zu of the --at instants lie after the last event (%s %.6f s%s; --at takes "
               "seconds from the first event%s, or a unit: 500ms, 20us)\n",
               command, count, read ? "the events read span" : "the recording is", seconds_between(first_t_us, last_t_us),
               read ? "" : " long", read ? " read" : "");
}

}  // namespace evlife::cli
