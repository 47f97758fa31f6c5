// HDF5's file signature (its superblock at offset 0, as every writer evlife
// reads puts it): how the event reader's sniffer and the augmented reader
// tell an HDF5 file by its first bytes. No libhdf5 needed.
#pragma once

#include <cstddef>
#include <cstring>
#include <string_view>

namespace evlife::io::detail {

inline constexpr std::string_view kHdf5Signature{"\x89HDF\r\n\x1a\n", 8};

/// True when `head` (a file's first bytes) starts with HDF5's signature.
inline bool starts_with_hdf5_signature(const void* head, std::size_t size) noexcept {
  return size >= kHdf5Signature.size() && std::memcmp(head, kHdf5Signature.data(), kHdf5Signature.size()) == 0;
}

}  // namespace evlife::io::detail
