// Before allocating the estimators' state (~80 bytes per pixel each) or a
// synthetic scene's background (a frame: render/frame_memory.h): a refusal naming what it would take when that
// exceeds the memory this machine has available, instead of an OOM kill or a
// bare std::bad_alloc.
#pragma once

#include <optional>
#include <string>

#include "evlife/algo/event.h"
#include "evlife/io/synthetic_scene.h"
#include "evlife/io/textured_scene.h"

namespace evlife::cli {

/// The refusal of a synthetic scene whose background (noise, hot pixels)
/// would not fit: one slice of it (the streamed scenes), or all of it (the
/// textured scene, generated whole).
std::optional<std::string> scene_memory_refusal(const io::SceneSpec& spec);
std::optional<std::string> scene_memory_refusal(const io::TexturedSceneSpec& spec);

/// "needs ..." when `estimators` estimators for `sensor` exceed MemAvailable
/// (/proc/meminfo); nothing when they fit or it is unknown.
std::optional<std::string> estimator_memory_refusal(SensorSize sensor, int estimators);

}  // namespace evlife::cli
