// Cost of reading jAER AEDAT 2.0 from a DAVIS346 (no such recording is
// shared): a file written by the test-only DAVIS writer, 1 M DVS events with,
// per 10,000 events, a 346x260 APS frame's worth of samples cut to 2,000
// records and one IMU sample — the decoder skips those, so items = DVS events
// and bytes = the whole file. Run:
//   build/bench/bench_aedat2_davis --benchmark_repetitions=3
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "davis_aedat2_writer.h"
#include "evlife/io/event_reader.h"

namespace {

std::string write_davis346(std::int64_t& dvs_events) {
  evlife::test::DavisAedat2Writer f("eu.seebetter.ini.chips.davis.Davis346B", 346, 260);
  std::uint32_t t = 0;
  std::uint32_t state = 12345;
  dvs_events = 0;
  for (int block = 0; block < 100; ++block) {
    for (int i = 0; i < 10000; ++i, ++dvs_events) {
      state = state * 1664525u + 1013904223u;  // a fixed pseudo-random pixel sequence
      f.dvs(static_cast<int>((state >> 8) % 346), static_cast<int>((state >> 20) % 260), (state & 1u) != 0, t += 3);
    }
    for (int i = 0; i < 2000; ++i) f.aps(i % 346, i / 346, 0, i & 0x3FF, t);
    f.imu({1, 2, 3, 4, 5, 6, 7}, t);
  }
  const std::string path =
      (std::filesystem::temp_directory_path() / ("evlife_bench_davis_" + std::to_string(::getpid()) + ".aedat")).string();
  std::ofstream(path, std::ios::binary)
      .write(f.bytes().data(), static_cast<std::streamsize>(f.bytes().size()));
  return path;
}

void BM_Read_Aedat2_Davis346(benchmark::State& state) {
  std::int64_t per_file = 0;
  const std::string path = write_davis346(per_file);
  std::vector<evlife::Event> buffer(4096);
  std::int64_t events = 0;
  for (auto _ : state) {
    auto reader = evlife::io::open_event_reader(path);
    while (const std::size_t n = reader->read(buffer)) {
      events += static_cast<std::int64_t>(n);
      benchmark::DoNotOptimize(buffer.data());
    }
  }
  if (events != per_file * static_cast<std::int64_t>(state.iterations())) state.SkipWithError("event count");
  state.SetItemsProcessed(events);
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) *
                          static_cast<std::int64_t>(std::filesystem::file_size(path)));
  std::filesystem::remove(path);
}
BENCHMARK(BM_Read_Aedat2_Davis346)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
