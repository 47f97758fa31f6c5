// The attributes the HDF5 reader reads (a sensor's width and height, a time
// column's units), here once for the reader and for the probe that repeats
// its steps in a child process (hdf5_open_probe.h): a corrupt attribute can
// hang or crash libhdf5 as a corrupt dataset can.
#pragma once

#include <hdf5.h>

#include <cstdint>
#include <optional>
#include <string>

namespace evlife::io {

/// An integer attribute of `object`; nullopt when there is none or it does not read.
std::optional<std::int64_t> read_int_attribute(hid_t object, const char* name);

/// A scalar string attribute, fixed-length (evlife's writer) or variable-length
/// (h5py's str); nullopt when there is none, or it is no such string.
std::optional<std::string> read_string_attribute(hid_t object, const char* name);

}  // namespace evlife::io
