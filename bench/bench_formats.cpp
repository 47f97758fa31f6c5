// Decode speed of each recording format (events/s, one core): the whole file
// read through its reader into a 64 Ki-event buffer, per iteration. Files are
// in the page cache after the first iteration, so this is the decoder's speed.
// "decoder" = open_unchecked_event_reader (format decoding alone);
// "checked" = open_event_reader (plus sensor-bounds and time-order checks).
//   ./build/bench/bench_formats --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "evlife/io/event_reader.h"
#include "evlife/io/hdf5_writer.h"

#include <hdf5.h>

namespace {

const std::string kData = EVLIFE_SHARED_DATA_DIR;

// A 2 M-event HDF5 file written once by the evlife writer (no HDF5 sample exists).
const std::string& hdf5_file() {
  static const std::string path = [] {
    const std::string p = (std::filesystem::temp_directory_path() /
                           ("evlife_bench_formats_" + std::to_string(::getpid()) + ".h5"))
                              .string();
    auto writer = evlife::io::open_hdf5_event_writer(p, evlife::SensorSize{640, 480});
    std::vector<evlife::Event> events(1 << 16);
    std::int64_t t_us = 0;
    std::uint32_t state = 1;
    for (int batch = 0; batch < 32; ++batch) {
      for (auto& e : events) {
        state = state * 1664525u + 1013904223u;
        t_us += state >> 30;
        e = evlife::Event{t_us, static_cast<std::uint16_t>((state >> 8) % 640),
                          static_cast<std::uint16_t>((state >> 18) % 480),
                          (state & 1u) != 0 ? std::int8_t{1} : std::int8_t{-1}};
      }
      writer->write(events);
    }
    writer->close();
    return p;
  }();
  return path;
}

// The same events in DSEC's layout (events/{x,y,t,p}), chunked but not
// compressed: the reader's own cost, without zlib's.
const std::string& hdf5_dsec_uncompressed_file() {
  static const std::string path = [] {
    const std::string p = (std::filesystem::temp_directory_path() /
                           ("evlife_bench_formats_dsec_" + std::to_string(::getpid()) + ".h5"))
                              .string();
    constexpr hsize_t kCount = 2 << 20;
    std::vector<std::uint16_t> x(kCount), y(kCount);
    std::vector<std::int64_t> t(kCount);
    std::vector<std::uint8_t> pol(kCount);
    std::uint32_t state = 1;
    std::int64_t t_us = 0;
    for (hsize_t i = 0; i < kCount; ++i) {
      state = state * 1664525u + 1013904223u;
      t_us += state >> 30;
      x[i] = static_cast<std::uint16_t>((state >> 8) % 640);
      y[i] = static_cast<std::uint16_t>((state >> 18) % 480);
      t[i] = t_us;
      pol[i] = static_cast<std::uint8_t>(state & 1u);
    }
    const hid_t file = H5Fcreate(p.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    const hid_t group = H5Gcreate2(file, "events", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    const hid_t space = H5Screate_simple(1, &kCount, nullptr);
    const hid_t props = H5Pcreate(H5P_DATASET_CREATE);
    const hsize_t chunk = 1 << 16;
    H5Pset_chunk(props, 1, &chunk);
    auto put = [&](const char* name, hid_t type, const void* data) {
      const hid_t d = H5Dcreate2(group, name, type, space, H5P_DEFAULT, props, H5P_DEFAULT);
      H5Dwrite(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data);
      H5Dclose(d);
    };
    put("x", H5T_NATIVE_UINT16, x.data());
    put("y", H5T_NATIVE_UINT16, y.data());
    put("t", H5T_NATIVE_INT64, t.data());
    put("p", H5T_NATIVE_UINT8, pol.data());
    H5Pclose(props);
    H5Sclose(space);
    H5Gclose(group);
    H5Fclose(file);
    return p;
  }();
  return path;
}

void decode(benchmark::State& state, const std::string& path, bool checked) {
  std::vector<evlife::Event> buffer(1 << 16);
  std::int64_t events = 0;
  std::int64_t bytes = 0;
  for (auto _ : state) {
    auto reader = checked ? evlife::io::open_event_reader(path)
                          : evlife::io::open_unchecked_event_reader(path);
    while (const std::size_t n = reader->read(buffer)) {
      events += static_cast<std::int64_t>(n);
      benchmark::DoNotOptimize(buffer.data());
    }
    bytes += static_cast<std::int64_t>(std::filesystem::file_size(path));
  }
  state.SetItemsProcessed(events);
  state.SetBytesProcessed(bytes);
}

void register_all() {
  struct File {
    const char* name;
    std::string path;
  };
  const File files[] = {
      {"aedat4", kData + "/aedat4/sample.aedat4"},
      {"evt2", kData + "/evt2/evt2_sample.raw"},
      {"evt3", kData + "/evt3/evt3_sample.raw"},
      {"prophesee_dat", kData + "/prophesee_dat/NCARS_obj_004397_td.dat"},
      {"hdf5", ""},
      {"hdf5_dsec_uncompressed", "dsec"},
  };
  for (const File& f : files) {
    for (const bool checked : {false, true}) {
      const std::string name = std::string("BM_Decode/") + f.name + (checked ? "/checked" : "/decoder");
      benchmark::RegisterBenchmark(name.c_str(), [path = f.path, checked](benchmark::State& s) {
        decode(s, path.empty() ? hdf5_file() : path == "dsec" ? hdf5_dsec_uncompressed_file() : path, checked);
      })->Unit(benchmark::kMillisecond)->MinTime(0.5);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  register_all();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  std::error_code ec;
  std::filesystem::remove(hdf5_file(), ec);
  std::filesystem::remove(hdf5_dsec_uncompressed_file(), ec);
  return 0;
}
