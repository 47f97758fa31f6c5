// libFuzzer target: the HDF5 reader's LZF filter (io/formats/src/hdf5_lzf_filter.cpp),
// called as libhdf5 calls it on a chunk read from a file. Input: 4 bytes of
// the chunk size h5py states (cd_values[2], little-endian, kept below 1 MiB
// so that every input runs fast; 0 = not stated: refused), then the stored chunk.
// A finding: a sanitizer report, or a chunk that decompresses and then does
// not come back the same through the filter's own compression.
#include <hdf5.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "hdf5_lzf_filter.h"

namespace {

// The filter on a copy of `bytes` in a libhdf5 buffer, as libhdf5 hands it
// over; returns the bytes used (0: refused) and leaves the buffer in `*out`.
std::size_t run_filter(unsigned flags, unsigned stated, const void* bytes, std::size_t size, void** out,
                       std::size_t* out_size) {
  *out_size = size == 0 ? 1 : size;
  *out = H5allocate_memory(*out_size, false);
  if (*out == nullptr) std::abort();
  if (size != 0) std::memcpy(*out, bytes, size);
  const unsigned cd_values[3] = {4, 1, stated};
  return evlife::io::detail::hdf5_lzf_filter(flags, 3, cd_values, size, out_size, out);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 4) return 0;
  const unsigned stated = (static_cast<unsigned>(data[0]) | static_cast<unsigned>(data[1]) << 8 |
                           static_cast<unsigned>(data[2]) << 16) & 0xFFFFFU;
  void* chunk = nullptr;
  std::size_t chunk_size = 0;
  const std::size_t got = run_filter(H5Z_FLAG_REVERSE, stated, data + 4, size - 4, &chunk, &chunk_size);
  if (got > chunk_size) std::abort();  // more bytes than the buffer holds
  if (got != 0) {
    void* packed = nullptr;
    std::size_t packed_size = 0;
    const std::size_t packed_bytes = run_filter(0, 0, chunk, got, &packed, &packed_size);
    if (packed_bytes != 0) {
      void* back = nullptr;
      std::size_t back_size = 0;
      const std::size_t back_bytes =
          run_filter(H5Z_FLAG_REVERSE, static_cast<unsigned>(got), packed, packed_bytes, &back, &back_size);
      if (back_bytes != got || std::memcmp(back, chunk, got) != 0) std::abort();
      H5free_memory(back);
    }
    H5free_memory(packed);
  }
  H5free_memory(chunk);
  return 0;
}
