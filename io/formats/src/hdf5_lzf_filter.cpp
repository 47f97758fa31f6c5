#include "hdf5_lzf_filter.h"

#include <hdf5.h>
#include <lzf.h>

#include <algorithm>
#include <cerrno>
#include <climits>
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
  const std::size_t stated = cd_nelmts >= 3 ? cd_values[2] : 0;
  std::size_t out_size = stated != 0 ? stated : *buf_size;
  for (;;) {
    if (out_size == 0 || out_size > kHdf5MaxChunkBytes) return 0;
    void* out = H5allocate_memory(out_size, /*clear=*/true);  // a short chunk leaves zeros, never garbage
    if (out == nullptr) return 0;
    errno = 0;
    const unsigned got = lzf_decompress(*buf, static_cast<unsigned>(nbytes), out, static_cast<unsigned>(out_size));
    if (got != 0 && stated != 0 && got != stated) {  // not the chunk h5py compressed: corrupt
      H5free_memory(out);
      return 0;
    }
    if (got != 0) {
      H5free_memory(*buf);
      *buf = out;
      *buf_size = out_size;
      return got;
    }
    H5free_memory(out);
    // E2BIG: a chunk larger than it said (or no size given): twice the room,
    // up to the largest chunk read. Anything else (EINVAL): corrupt data.
    if (errno != E2BIG || out_size == kHdf5MaxChunkBytes) return 0;
    out_size = std::min<std::size_t>(2 * out_size, kHdf5MaxChunkBytes);
  }
}

void register_hdf5_lzf_filter() {
  static std::once_flag once;
  std::call_once(once, [] {
    const Hdf5ErrorSilencer silence;  // looking for a plugin may fail: not an error
    if (H5Zfilter_avail(kHdf5LzfFilterId) > 0) return;
    static const H5Z_class2_t lzf = {
        H5Z_CLASS_T_VERS, kHdf5LzfFilterId,
        /*encoder_present=*/1, /*decoder_present=*/1, "lzf (evlife's, over liblzf)",
        /*can_apply=*/nullptr, /*set_local=*/nullptr, &hdf5_lzf_filter};
    H5Zregister(&lzf);
  });
}

}  // namespace evlife::io::detail
