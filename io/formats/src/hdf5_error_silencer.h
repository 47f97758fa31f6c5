// Turns off the HDF5 library's printing of error stacks for one scope (we
// report errors ourselves) and restores the previous handler afterwards.
#pragma once

#include <hdf5.h>

namespace evlife::io {

class Hdf5ErrorSilencer {
 public:
  Hdf5ErrorSilencer() noexcept {
    H5Eget_auto2(H5E_DEFAULT, &function_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~Hdf5ErrorSilencer() { H5Eset_auto2(H5E_DEFAULT, function_, data_); }
  Hdf5ErrorSilencer(const Hdf5ErrorSilencer&) = delete;
  Hdf5ErrorSilencer& operator=(const Hdf5ErrorSilencer&) = delete;

 private:
  H5E_auto2_t function_ = nullptr;
  void* data_ = nullptr;
};

}  // namespace evlife::io
