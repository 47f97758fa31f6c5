// The active-event map moved to algo/ (evlife/algo/active_event_map.h, no
// OpenCV): this header keeps the old render:: names compiling.
#pragma once

#include "evlife/algo/active_event_map.h"

namespace evlife::render {
using ActiveEventSet = evlife::ActiveEventMap;
using ActiveEventSetStats = evlife::ActiveEventMapStats;
}  // namespace evlife::render
