// Private: compressed streams cut short — the chunk a ROS 1 recorder was
// writing when it was killed (librosbag streams bz2 / LZ4 chunks to disk) —
// decoded as far as their whole blocks go.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace evlife::io::detail {

/// A bz2 stream cut short decoded as far as whole blocks go into `out` (at
/// most about `max_bytes`); true if bytes were left that no whole block holds
/// (all but the 4-byte stream header "BZh9", unless the stream ended; bz2
/// blocks are not byte-aligned, so a cut exactly at a block's end is not told
/// apart).
bool inflate_cut_bz2(std::span<const std::uint8_t> in, std::vector<std::uint8_t>& out, std::size_t max_bytes);

/// The same for an LZ4 frame: true if a block was begun and not finished
/// (LZ4F asks for exactly a block header's 4 bytes between blocks).
bool inflate_cut_lz4(std::span<const std::uint8_t> in, std::vector<std::uint8_t>& out, std::size_t max_bytes);

}  // namespace evlife::io::detail
