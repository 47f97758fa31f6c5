// Before allocating the estimators' state (~80 bytes per pixel each): a
// refusal naming what it would take when that exceeds the memory this machine
// has available, instead of an OOM kill or a bare std::bad_alloc.
#pragma once

#include <optional>
#include <string>

#include "evlife/algo/event.h"

namespace evlife::cli {

/// "needs ..." when `estimators` estimators for `sensor` exceed MemAvailable
/// (/proc/meminfo); nothing when they fit or it is unknown.
std::optional<std::string> estimator_memory_refusal(SensorSize sensor, int estimators);

}  // namespace evlife::cli
