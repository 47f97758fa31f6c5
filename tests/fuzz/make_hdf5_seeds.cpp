// Writes the HDF5 seeds of the layouts of other tools into tests/fuzz/corpus/hdf5/
// (no Python HDF5 on the CI image; the C API writes what h5py would). Run by
// hand, only to change the seeds (python/tests/test_read.py knows their events:
// event i at x = 7i mod 346 (240; M3ED 1280), y = 5i mod 260 (180; 720), p = +1
// for odd i, 37 µs apart):
//   g++ -std=c++20 -o /tmp/make_hdf5_seeds tests/fuzz/make_hdf5_seeds.cpp -Itests/support -I/usr/include/hdf5/serial
//     -L/usr/lib/x86_64-linux-gnu/hdf5/serial -lhdf5 && /tmp/make_hdf5_seeds tests/fuzz/corpus/hdf5
#include <hdf5.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "hdf5_dataset.h"

namespace {

constexpr int kEvents = 30;
constexpr hsize_t kChunk = 16;  // two storage chunks, deflate: as the tools write

// `values` as a dataset at `name`: 1-D, or N×4 (`table`); chunked and deflated unless not `chunked`.
template <typename T>
void write(hid_t where, const char* name, hid_t file_type, hid_t memory_type, const std::vector<T>& values,
           bool table, bool chunked = true) {
  const std::vector<hsize_t> inner = table ? std::vector<hsize_t>{4} : std::vector<hsize_t>{};
  if (!evlife::test::write_hdf5_dataset(where, name, file_type, memory_type, values, inner,
                                        chunked ? evlife::test::Hdf5Storage{kChunk, 1} : evlife::test::Hdf5Storage{})) {
    std::fprintf(stderr, "make_hdf5_seeds: cannot write %s\n", name);
    std::exit(1);
  }
}

void event_utils(const std::string& path, bool numpy_bool) {
  std::vector<std::int16_t> xs, ys;
  std::vector<double> ts;
  std::vector<std::int8_t> ps;
  for (int i = 0; i < kEvents; ++i) {
    xs.push_back(static_cast<std::int16_t>((i * 7) % 240));
    ys.push_back(static_cast<std::int16_t>((i * 5) % 180));
    ts.push_back(0.25 + 37e-6 * i);
    ps.push_back(static_cast<std::int8_t>(i % 2));
  }
  const hid_t file = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  const hid_t group = H5Gcreate2(file, "events", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  write(group, "xs", H5T_STD_I16LE, H5T_NATIVE_INT16, xs, false, !numpy_bool);
  write(group, "ys", H5T_STD_I16LE, H5T_NATIVE_INT16, ys, false, !numpy_bool);
  write(group, "ts", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, ts, false, !numpy_bool);
  if (numpy_bool) {  // h5py's bool: an enum of int8 {FALSE = 0, TRUE = 1}
    const hid_t boolean = H5Tenum_create(H5T_NATIVE_INT8);
    const std::int8_t no = 0, yes = 1;
    H5Tenum_insert(boolean, "FALSE", &no);
    H5Tenum_insert(boolean, "TRUE", &yes);
    write(group, "ps", boolean, boolean, ps, false, false);
    H5Tclose(boolean);
  } else {
    write(group, "ps", H5T_STD_U8LE, H5T_NATIVE_INT8, ps, false);
  }
  H5Gclose(group);
  H5Fclose(file);
}

}  // namespace

int main(int argc, char** argv) {
  const std::string dir = argc > 1 ? argv[1] : ".";
  {  // v2e --dvs_h5: events, uint32 rows [t µs, x, y, p 0/1]
    std::vector<std::uint32_t> rows;
    for (int i = 0; i < kEvents; ++i) {
      for (const int v : {1000 + 37 * i, (i * 7) % 346, (i * 5) % 260, i % 2}) rows.push_back(static_cast<std::uint32_t>(v));
    }
    const hid_t file = H5Fcreate((dir + "/v2e_30ev.h5").c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    write(file, "events", H5T_STD_U32LE, H5T_NATIVE_UINT32, rows, true);
    H5Fclose(file);
  }
  {  // MVSEC: davis/left/events, float64 rows [x, y, t s, p ±1]
    std::vector<double> rows;
    for (int i = 0; i < kEvents; ++i) {
      for (const double v : {double((i * 7) % 346), double((i * 5) % 260), 1504645177.0 + 37e-6 * i, i % 2 ? 1.0 : -1.0})
        rows.push_back(v);
    }
    const hid_t file = H5Fcreate((dir + "/mvsec_30ev.h5").c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    write(file, "davis/left/events", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, rows, true);
    H5Fclose(file);
  }
  event_utils(dir + "/event_utils_30ev.h5", false);
  event_utils(dir + "/event_utils_bool_30ev.h5", true);
  {  // M3ED: prophesee/left/{x,y,t,p} (uint16, int64 µs, int8 0/1) + calib/resolution, a right camera
    const hid_t file = H5Fcreate((dir + "/m3ed_30ev.h5").c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    for (const std::string camera : {"prophesee/left", "prophesee/right"}) {
      std::vector<std::uint16_t> x, y;
      std::vector<std::int64_t> t;
      std::vector<std::int8_t> p;
      for (int i = 0; i < kEvents; ++i) {
        x.push_back(static_cast<std::uint16_t>((i * 7) % 1280));
        y.push_back(static_cast<std::uint16_t>((i * 5) % 720));
        t.push_back(1000 + 37 * i);
        p.push_back(static_cast<std::int8_t>(i % 2));
      }
      write(file, (camera + "/x").c_str(), H5T_STD_U16LE, H5T_NATIVE_UINT16, x, false);
      write(file, (camera + "/y").c_str(), H5T_STD_U16LE, H5T_NATIVE_UINT16, y, false);
      write(file, (camera + "/t").c_str(), H5T_STD_I64LE, H5T_NATIVE_INT64, t, false);
      write(file, (camera + "/p").c_str(), H5T_STD_I8LE, H5T_NATIVE_INT8, p, false);
      write(file, (camera + "/calib/resolution").c_str(), H5T_STD_I64LE, H5T_NATIVE_INT64,
            std::vector<std::int64_t>{1280, 720}, false, false);
    }
    H5Fclose(file);
  }
  return 0;
}
