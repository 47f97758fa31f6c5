#include "hdf5_attributes.h"

namespace evlife::io {

std::optional<std::int64_t> read_int_attribute(hid_t object, const char* name) {
  if (H5Aexists(object, name) <= 0) return std::nullopt;
  const hid_t attribute = H5Aopen(object, name, H5P_DEFAULT);
  if (attribute < 0) return std::nullopt;
  std::int64_t value = 0;
  const herr_t status = H5Aread(attribute, H5T_NATIVE_INT64, &value);
  H5Aclose(attribute);
  if (status < 0) return std::nullopt;
  return value;
}

std::optional<std::string> read_string_attribute(hid_t object, const char* name) {
  if (H5Aexists(object, name) <= 0) return std::nullopt;
  const hid_t attribute = H5Aopen(object, name, H5P_DEFAULT);
  if (attribute < 0) return std::nullopt;
  std::optional<std::string> value;
  const hid_t type = H5Aget_type(attribute);
  const hid_t space = H5Aget_space(attribute);
  if (type >= 0 && space >= 0 && H5Tget_class(type) == H5T_STRING && H5Sget_simple_extent_npoints(space) == 1) {
    const hid_t memory = H5Tcopy(H5T_C_S1);
    H5Tset_cset(memory, H5Tget_cset(type));  // h5py's str is UTF-8: libhdf5 converts no cset to another
    if (H5Tis_variable_str(type) > 0) {
      char* text = nullptr;
      if (H5Tset_size(memory, H5T_VARIABLE) >= 0 && H5Aread(attribute, memory, &text) >= 0 && text != nullptr) {
        value = std::string(text);
        H5free_memory(text);
      }
    } else if (const std::size_t size = H5Tget_size(type); size > 0 && size <= 256) {
      std::string buffer(size + 1, '\0');  // + its terminator (the stored text may fill `size`)
      if (H5Tset_size(memory, size + 1) >= 0 && H5Aread(attribute, memory, buffer.data()) >= 0)
        value = buffer.substr(0, buffer.find('\0'));
    }
    H5Tclose(memory);
  }
  if (space >= 0) H5Sclose(space);
  if (type >= 0) H5Tclose(type);
  H5Aclose(attribute);
  return value;
}

}  // namespace evlife::io
