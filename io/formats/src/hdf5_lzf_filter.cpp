#include "hdf5_lzf_filter.h"

#include <hdf5.h>
#include <lzf.h>

#include <climits>
#include <cstdint>
#include <mutex>

#include "hdf5_error_silencer.h"

namespace evlife::io::detail {

std::size_t hdf5_lzf_filter(unsigned flags, std::size_t cd_nelmts, const unsigned cd_values[], std::size_t nbytes,
                            std::size_t* buf_size, void** buf) {
  if (nbytes > UINT_MAX || nbytes > *buf_size) return 0;  // liblzf counts in unsigned int
  if ((flags & H5Z_FLAG_REVERSE) == 0U) {
    // Compressing (h5py's way: no larger than the input, else 0 and HDF5
    // stores the chunk as it is). evlife writes no LZF; a process that
    // registered this filter must still be able to (h5py beside evlife).
    if (nbytes == 0) return 0;
    void* out = H5allocate_memory(nbytes, false);
    if (out == nullptr) return 0;
    const unsigned packed = lzf_compress(*buf, static_cast<unsigned>(nbytes), out, static_cast<unsigned>(nbytes));
    if (packed == 0) {
      H5free_memory(out);
      return 0;
    }
    H5free_memory(*buf);
    *buf = out;
    *buf_size = nbytes;
    return packed;
  }
  // The chunk's size, as h5py's set_local (and set_lzf_chunk_size below)
  // states it: libhdf5 copies a whole chunk out of what the filter returns,
  // so anything but exactly that many bytes is refused (the reader checks the
  // stated size against the dataset's chunks when it opens the file).
  const std::size_t stated = cd_nelmts >= 3 ? cd_values[2] : 0;
  if (stated == 0 || stated > kHdf5MaxChunkBytes) return 0;
  void* out = H5allocate_memory(stated, false);
  if (out == nullptr) return 0;
  const unsigned got = lzf_decompress(*buf, static_cast<unsigned>(nbytes), out, static_cast<unsigned>(stated));
  if (got != stated) {  // corrupt (EINVAL), longer (E2BIG) or shorter than the chunk
    H5free_memory(out);
    return 0;
  }
  H5free_memory(*buf);
  *buf = out;
  *buf_size = stated;
  return got;
}

namespace {

// set_local (H5Z_set_local_func_t): states the dataset's chunk size in
// cd_values[2], as h5py does, so that a chunk this process writes decodes.
herr_t set_lzf_chunk_size(hid_t properties, hid_t type, hid_t /*space*/) {
  hsize_t dims[H5S_MAX_RANK] = {};
  const int rank = H5Pget_chunk(properties, H5S_MAX_RANK, dims);
  const std::size_t element = H5Tget_size(type);
  if (rank <= 0 || element == 0) return -1;
  std::uint64_t bytes = element;
  for (int i = 0; i < rank; ++i) {
    if (dims[i] == 0 || bytes > kHdf5MaxChunkBytes / dims[i]) return -1;
    bytes *= dims[i];
  }
  unsigned flags = 0;
  std::size_t count = 3;
  unsigned values[3] = {};
  if (H5Pget_filter_by_id2(properties, kHdf5LzfFilterId, &flags, &count, values, 0, nullptr, nullptr) < 0) return -1;
  values[0] = 4;       // h5py's filter version
  values[1] = 0x0105;  // liblzf's version (LZF_VERSION)
  values[2] = static_cast<unsigned>(bytes);
  return H5Pmodify_filter(properties, kHdf5LzfFilterId, flags, 3, values);
}

}  // namespace

void register_hdf5_lzf_filter() {
  static std::once_flag once;
  std::call_once(once, [] {
    const Hdf5ErrorSilencer silence;  // looking for a plugin may fail: not an error
    if (H5Zfilter_avail(kHdf5LzfFilterId) > 0) return;
    static const H5Z_class2_t lzf = {
        H5Z_CLASS_T_VERS, kHdf5LzfFilterId,
        /*encoder_present=*/1, /*decoder_present=*/1, "lzf (evlife's, over liblzf)",
        /*can_apply=*/nullptr, &set_lzf_chunk_size, &hdf5_lzf_filter};
    H5Zregister(&lzf);
  });
}

}  // namespace evlife::io::detail
