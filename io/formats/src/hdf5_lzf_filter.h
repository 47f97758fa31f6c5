// h5py's LZF compression (HDF5 filter 32000; `compression="lzf"`, common in
// files written from Python) for the HDF5 reader. Debian's hdf5-plugin-lzf
// cannot be loaded on its own (its liblzf_filter.so leaves lzf_decompress
// undefined), so evlife registers the filter over Debian's liblzf instead.
#pragma once

#include <cstddef>
#include <cstdint>

namespace evlife::io::detail {

/// h5py's filter id (registered with The HDF Group).
inline constexpr int kHdf5LzfFilterId = 32000;

/// libhdf5 allocates a whole storage chunk to read any part of it; a corrupt
/// chunk size (fuzzing found 4 GB) must not reach that allocation. The reader
/// refuses datasets with larger chunks, so no chunk decompresses to more.
inline constexpr std::uint64_t kHdf5MaxChunkBytes = std::uint64_t{256} << 20;

/// Registers the filter, once per process, unless a working LZF filter is
/// already there (h5py imported in the same Python process, a plugin).
void register_hdf5_lzf_filter();

/// The filter callback (H5Z_func_t): replaces `*buf` (`nbytes` used of
/// `*buf_size`) by its decompression (H5Z_FLAG_REVERSE) or compression;
/// returns the bytes used, 0 on corrupt input (or a chunk that does not
/// shrink). `cd_values[2]`, where h5py stores it, is the chunk's size in
/// bytes: a chunk decompresses to exactly that, or is refused. Public for
/// the fuzz target.
std::size_t hdf5_lzf_filter(unsigned flags, std::size_t cd_nelmts, const unsigned cd_values[], std::size_t nbytes,
                            std::size_t* buf_size, void** buf);

}  // namespace evlife::io::detail
