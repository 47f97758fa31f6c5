// Before allocating the estimators' state (~80 bytes per pixel each): a
// refusal naming what it would take when that exceeds the memory this machine
// has available, instead of an OOM kill or a bare std::bad_alloc.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "evlife/algo/event.h"

namespace evlife::cli {

/// "N GB, more than the A GB of memory available" when `bytes` exceed
/// MemAvailable (/proc/meminfo); nothing when they fit or it is unknown.
std::optional<std::string> memory_shortfall(std::uint64_t bytes);

/// The refusal of a synthetic scene whose background (noise, hot pixels)
/// would not fit: `bytes` held at once (io::scene_reader_memory_bytes, or
/// io::textured_scene_memory_bytes when the scene is generated `whole`).
std::optional<std::string> scene_memory_refusal(std::uint64_t bytes, bool whole);

/// "needs ..." when `estimators` estimators for `sensor` exceed MemAvailable
/// (/proc/meminfo); nothing when they fit or it is unknown.
std::optional<std::string> estimator_memory_refusal(SensorSize sensor, int estimators);

}  // namespace evlife::cli
