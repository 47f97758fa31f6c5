// The memory this machine has available, and the refusal text of what would
// exceed it: a large scene, the estimators' state or a frame is refused up
// front, naming what it takes, instead of an OOM kill or a bare bad_alloc.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace evlife::io {

/// MemAvailable of /proc/meminfo in bytes, what those figures are weighed
/// against (`evlife synth`, evlife.synth); nothing when it is unknown.
std::optional<std::uint64_t> available_memory_bytes();

/// "12.3 GB": `bytes` in decimal gigabytes, one decimal.
std::string gigabytes_text(std::uint64_t bytes);

/// ", more than the A GB of memory available" when `bytes` exceed
/// MemAvailable, or what an address-space limit (`ulimit -v`) leaves the
/// process to map (said as such); nothing when they fit or it is unknown.
std::optional<std::string> beyond_available_memory(std::uint64_t bytes);

}  // namespace evlife::io
