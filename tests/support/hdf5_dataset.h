// One HDF5 dataset written in one call: what the HDF5 tests, bench_formats
// and the hand-run seed generator (tests/fuzz/make_hdf5_seeds.cpp) write the
// layouts of other tools with. Header-only, the HDF5 C API alone: the seed
// generator is compiled by hand, outside CMake.
#pragma once

#include <hdf5.h>

#include <algorithm>
#include <string>
#include <vector>

namespace evlife::test {

// How the dataset is stored: chunks of `chunk_rows` rows (at most the
// dataset's rows; 0: contiguous), deflated at level `deflate` (< 0: not).
struct Hdf5Storage {
  hsize_t chunk_rows = 0;
  int deflate = -1;
};

/// `values` as the dataset `name` of `where`, of `file_type` (read from
/// `memory_type`): 1-D, or N rows of `inner` dimensions (a table of columns,
/// a stack of frames); the groups on the path of `name` are created. False
/// when HDF5 refuses to create or to write it.
template <typename T>
bool write_hdf5_dataset(hid_t where, const std::string& name, hid_t file_type, hid_t memory_type,
                        const std::vector<T>& values, const std::vector<hsize_t>& inner = {},
                        Hdf5Storage storage = {}) {
  std::vector<hsize_t> size{values.size()};
  for (const hsize_t d : inner) {
    size[0] /= d;
    size.push_back(d);
  }
  const auto rank = static_cast<int>(size.size());
  const hid_t links = H5Pcreate(H5P_LINK_CREATE);
  H5Pset_create_intermediate_group(links, 1);
  const hid_t space = H5Screate_simple(rank, size.data(), nullptr);
  const hid_t properties = H5Pcreate(H5P_DATASET_CREATE);
  if (storage.chunk_rows > 0) {
    std::vector<hsize_t> chunk = size;
    chunk[0] = std::min(storage.chunk_rows, size[0]);
    H5Pset_chunk(properties, rank, chunk.data());
    if (storage.deflate >= 0) H5Pset_deflate(properties, static_cast<unsigned>(storage.deflate));
  }
  const hid_t dataset = H5Dcreate2(where, name.c_str(), file_type, space, links, properties, H5P_DEFAULT);
  const bool ok =
      dataset >= 0 && H5Dwrite(dataset, memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()) >= 0;
  if (dataset >= 0) H5Dclose(dataset);
  H5Pclose(properties);
  H5Sclose(space);
  H5Pclose(links);
  return ok;
}

}  // namespace evlife::test
