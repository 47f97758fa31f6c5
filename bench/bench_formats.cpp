// Decode speed of each recording format (events/s, one core): the whole file
// read through its reader into a 64 Ki-event buffer, per iteration. Files are
// in the page cache after the first iteration, so this is the decoder's speed.
// "decoder" = open_unchecked_event_reader (format decoding alone);
// "checked" = open_event_reader (plus sensor-bounds and time-order checks).
//   ./build/bench/bench_formats --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "evlife/io/event_reader.h"
#include "evlife/io/hdf5_writer.h"
#include "hdf5_dataset.h"

#include <hdf5.h>

namespace {

const std::string kData = EVLIFE_SHARED_DATA_DIR;

constexpr std::size_t kSyntheticEvents = 2 << 20;

// The 2 M synthetic events of every HDF5 file here (no HDF5 sample exists):
// a 640x480 sensor, times rising by 0-3 µs.
const std::vector<evlife::Event>& synthetic_events() {
  static const std::vector<evlife::Event> events = [] {
    std::vector<evlife::Event> out(kSyntheticEvents);
    std::int64_t t_us = 0;
    std::uint32_t state = 1;
    for (auto& e : out) {
      state = state * 1664525u + 1013904223u;
      t_us += state >> 30;
      e = evlife::Event{t_us, static_cast<std::uint16_t>((state >> 8) % 640),
                        static_cast<std::uint16_t>((state >> 18) % 480),
                        (state & 1u) != 0 ? std::int8_t{1} : std::int8_t{-1}};
    }
    return out;
  }();
  return events;
}

std::string temp_path(const std::string& layout) {
  return (std::filesystem::temp_directory_path() /
          ("evlife_bench_formats_" + layout + "_" + std::to_string(::getpid()) + ".h5"))
      .string();
}

// Written by the evlife writer (shuffle + deflate 1).
std::string write_evlife_file() {
  const std::string p = temp_path("evlife");
  auto writer = evlife::io::open_hdf5_event_writer(p, evlife::SensorSize{640, 480});
  writer->write(synthetic_events());
  writer->close();
  return p;
}

// One dataset of `values` at `name`, chunked (64 Ki rows) but not compressed:
// the reader's own cost, without zlib's. `columns` 0: 1-D, else N×columns.
template <typename T>
void put(hid_t file, const char* name, hid_t type, const std::vector<T>& values, hsize_t columns = 0,
         evlife::test::Hdf5Storage storage = {1 << 16, -1}) {
  const std::vector<hsize_t> inner = columns > 0 ? std::vector<hsize_t>{columns} : std::vector<hsize_t>{};
  if (!evlife::test::write_hdf5_dataset(file, name, type, type, values, inner, storage)) {
    std::fprintf(stderr, "bench_formats: cannot write the HDF5 dataset %s\n", name);
    std::exit(1);
  }
}

// DSEC's layout: events/{x,y,t,p} (t µs, p 0/1), stored as `storage` says.
std::string write_dsec_file_stored(const std::string& layout, evlife::test::Hdf5Storage storage) {
  const auto& events = synthetic_events();
  std::vector<std::uint16_t> x, y;
  std::vector<std::int64_t> t;
  std::vector<std::uint8_t> pol;
  for (const auto& e : events) {
    x.push_back(e.x);
    y.push_back(e.y);
    t.push_back(e.t_us);
    pol.push_back(e.p > 0);
  }
  const std::string p = temp_path(layout);
  const hid_t file = H5Fcreate(p.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  put(file, "events/x", H5T_NATIVE_UINT16, x, 0, storage);
  put(file, "events/y", H5T_NATIVE_UINT16, y, 0, storage);
  put(file, "events/t", H5T_NATIVE_INT64, t, 0, storage);
  put(file, "events/p", H5T_NATIVE_UINT8, pol, 0, storage);
  H5Fclose(file);
  return p;
}

std::string write_dsec_file() { return write_dsec_file_stored("dsec", {1 << 16, -1}); }

// The same in chunks of 1 Mi rows, deflated (t: 8 MiB a chunk, beyond libhdf5's 1 MiB chunk
// cache, which the reader enlarges for such datasets).
std::string write_dsec_file_large_chunks() { return write_dsec_file_stored("dsec_large_chunks", {1 << 20, 1}); }

// v2e's table (uint32 rows t µs, x, y, p 0/1) and MVSEC's (float64 rows x,
// y, t s, p ±1): every cell converted to a double by the reader.
std::string write_v2e_file() {
  std::vector<std::uint32_t> rows;
  for (const auto& e : synthetic_events()) {
    for (const std::int64_t v : {e.t_us, std::int64_t{e.x}, std::int64_t{e.y}, std::int64_t{e.p > 0}})
      rows.push_back(static_cast<std::uint32_t>(v));
  }
  const std::string p = temp_path("v2e");
  const hid_t file = H5Fcreate(p.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  put(file, "events", H5T_NATIVE_UINT32, rows, 4);
  H5Fclose(file);
  return p;
}

std::string write_mvsec_file() {
  std::vector<double> rows;
  for (const auto& e : synthetic_events()) {
    for (const double v : {static_cast<double>(e.x), static_cast<double>(e.y), 1.5e9 + static_cast<double>(e.t_us) * 1e-6,
                           static_cast<double>(e.p)})
      rows.push_back(v);
  }
  const std::string p = temp_path("mvsec");
  const hid_t file = H5Fcreate(p.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  put(file, "davis/left/events", H5T_NATIVE_DOUBLE, rows, 4);
  H5Fclose(file);
  return p;
}

// The synthetic files, written on first use and removed at exit.
struct SyntheticFile {
  const char* name;
  std::string (*write)();
  std::string path;
};
SyntheticFile synthetic_files[] = {
    {"hdf5", &write_evlife_file, {}},
    {"hdf5_dsec_uncompressed", &write_dsec_file, {}},
    {"hdf5_dsec_deflated_1mi_row_chunks", &write_dsec_file_large_chunks, {}},
    {"hdf5_v2e_uncompressed", &write_v2e_file, {}},
    {"hdf5_mvsec_uncompressed", &write_mvsec_file, {}},
};

const std::string& synthetic_path(SyntheticFile& f) {
  if (f.path.empty()) f.path = f.write();
  return f.path;
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
  };
  const auto add = [](const char* name, bool checked, auto path) {
    const std::string full = std::string("BM_Decode/") + name + (checked ? "/checked" : "/decoder");
    auto* b = benchmark::RegisterBenchmark(full.c_str(), [path, checked](benchmark::State& s) {
      decode(s, path(), checked);
    });
    b->Unit(benchmark::kMillisecond)->MinTime(0.5);
    // HDF5 is read in a forked child (hdf5_read_child.h): this process's CPU
    // time misses the child's work, so its rates are per wall second.
    if (std::string_view(name).starts_with("hdf5")) b->UseRealTime();
  };
  for (const bool checked : {false, true}) {
    for (const File& f : files) add(f.name, checked, [p = f.path] { return p; });
    for (SyntheticFile& f : synthetic_files) add(f.name, checked, [&f] { return synthetic_path(f); });
  }
}

}  // namespace

int main(int argc, char** argv) {
  register_all();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  for (const SyntheticFile& f : synthetic_files) {
    std::error_code ec;
    if (!f.path.empty()) std::filesystem::remove(f.path, ec);
  }
  return 0;
}
