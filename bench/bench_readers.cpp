// Cost of reading each format (whole shared recordings, open included) and
// of writing augmented events. Items = events; run e.g.
//   build/bench/bench_readers --benchmark_min_time=1
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "evlife/io/augmented_event_reader.h"
#include "evlife/io/augmented_event_writer.h"
#include "evlife/io/event_reader.h"
#include "evlife/io/event_writer.h"

namespace {

const std::string kData = EVLIFE_SHARED_DATA_DIR;

// Opens and reads the whole file in batches of 4096 events.
void read_file(benchmark::State& state, const std::string& path, bool checked) {
  std::vector<evlife::Event> buffer(4096);
  std::int64_t events = 0;
  for (auto _ : state) {
    try {
      auto reader = checked ? evlife::io::open_event_reader(path)
                            : evlife::io::open_unchecked_event_reader(path);
      while (const std::size_t n = reader->read(buffer)) {
        events += static_cast<std::int64_t>(n);
        benchmark::DoNotOptimize(buffer.data());
      }
    } catch (const std::exception& e) {
      state.SkipWithError(e.what());
      return;
    }
  }
  state.SetItemsProcessed(events);
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) *
                          static_cast<std::int64_t>(std::filesystem::file_size(path)));
}

void BM_Read_Mat_Stripes(benchmark::State& s) { read_file(s, kData + "/reference/stripes.mat", true); }
void BM_Read_Mat_Garfield(benchmark::State& s) { read_file(s, kData + "/reference/garfield.mat", true); }
void BM_Read_Aedat2(benchmark::State& s) { read_file(s, kData + "/aedat2/alex_walking_again.aedat", true); }
void BM_Read_RpgText(benchmark::State& s) { read_file(s, kData + "/rpg_txt/slider_depth_events_chunk.txt", true); }
void BM_Read_Aedat4(benchmark::State& s) { read_file(s, kData + "/aedat4/sample.aedat4", true); }
void BM_Read_Evt2(benchmark::State& s) { read_file(s, kData + "/evt2/evt2_sample.raw", true); }
void BM_Read_Evt3(benchmark::State& s) { read_file(s, kData + "/evt3/evt3_sample.raw", true); }
void BM_Read_PropheseeDat(benchmark::State& s) { read_file(s, kData + "/prophesee_dat/NCARS_obj_004397_td.dat", true); }
// The validating wrapper's cost: same file, without the checks.
void BM_Read_Mat_Stripes_Unchecked(benchmark::State& s) { read_file(s, kData + "/reference/stripes.mat", false); }
void BM_Read_RpgText_Unchecked(benchmark::State& s) { read_file(s, kData + "/rpg_txt/slider_depth_events_chunk.txt", false); }
BENCHMARK(BM_Read_Mat_Stripes)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Read_Mat_Garfield)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Read_Aedat2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Read_RpgText)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Read_Aedat4)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Read_Evt2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Read_Evt3)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Read_PropheseeDat)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Read_Mat_Stripes_Unchecked)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Read_RpgText_Unchecked)->Unit(benchmark::kMillisecond);

// Plausible augmented events (what the estimator writes): 1280×720, some
// noise (lifetime 0), some without prediction.
std::vector<evlife::AugmentedEvent> augmented_events(std::size_t n) {
  std::vector<evlife::AugmentedEvent> out(n);
  std::uint64_t s = 7;
  for (std::size_t i = 0; i < n; ++i) {
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    evlife::AugmentedEvent& a = out[i];
    a.event = {static_cast<std::int64_t>(i * 3), static_cast<std::uint16_t>((s >> 20) % 1280),
               static_cast<std::uint16_t>((s >> 40) % 720), (s >> 63) ? std::int8_t{1} : std::int8_t{-1}};
    const float u = static_cast<float>((s >> 11) & 0xFFFFF) / 1048576.0f;
    a.lifetime_us = i % 5 == 0 ? 0.0f : 200.0f + 20000.0f * u;
    a.vx_px_s = a.lifetime_us > 0 ? 1e6f / a.lifetime_us * (u - 0.5f) : 0.0f;
    a.vy_px_s = a.lifetime_us > 0 ? 1e6f / a.lifetime_us * (0.3f - u) : 0.0f;
    a.prediction_error_us = i % 3 == 0 ? NAN : (u - 0.5f) * 3000.0f;
  }
  return out;
}

std::string temp_path(const char* ext) {
  return (std::filesystem::temp_directory_path() /
          ("evlife_bench_" + std::to_string(::getpid()) + ext)).string();
}

void write_augmented(benchmark::State& state, const char* ext) {
  const std::vector<evlife::AugmentedEvent> events = augmented_events(1 << 20);
  const std::string path = temp_path(ext);
  for (auto _ : state) {
    auto writer = evlife::io::open_augmented_writer(path, {1280, 720});
    for (std::size_t i = 0; i < events.size(); i += 4096)
      writer->write(std::span(events).subspan(i, 4096));
    writer->close();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) *
                          static_cast<std::int64_t>(events.size()));
  state.counters["bytes_per_event"] =
      static_cast<double>(std::filesystem::file_size(path)) / static_cast<double>(events.size());
  std::filesystem::remove(path);
}

void read_augmented(benchmark::State& state, const char* ext) {
  const std::vector<evlife::AugmentedEvent> events = augmented_events(1 << 20);
  const std::string path = temp_path(ext);
  {
    auto writer = evlife::io::open_augmented_writer(path, {1280, 720});
    writer->write(events);
    writer->close();
  }
  std::vector<evlife::AugmentedEvent> buffer(4096);
  std::int64_t n_total = 0;
  for (auto _ : state) {
    auto reader = evlife::io::open_augmented_reader(path);
    while (const std::size_t n = reader->read(buffer)) n_total += static_cast<std::int64_t>(n);
  }
  state.SetItemsProcessed(n_total);
  std::filesystem::remove(path);
}

void BM_Write_AugmentedCsv(benchmark::State& s) { write_augmented(s, ".csv"); }
void BM_Write_AugmentedBin(benchmark::State& s) { write_augmented(s, ".bin"); }
void BM_Read_AugmentedCsv(benchmark::State& s) { read_augmented(s, ".csv"); }
void BM_Read_AugmentedBin(benchmark::State& s) { read_augmented(s, ".bin"); }
BENCHMARK(BM_Write_AugmentedCsv)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Write_AugmentedBin)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Read_AugmentedCsv)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Read_AugmentedBin)->Unit(benchmark::kMillisecond);

void BM_Write_RpgText(benchmark::State& state) {
  const std::vector<evlife::AugmentedEvent> augmented = augmented_events(1 << 20);
  std::vector<evlife::Event> events;
  for (const auto& a : augmented) events.push_back(a.event);
  const std::string path = temp_path(".txt");
  for (auto _ : state) {
    auto writer = evlife::io::open_event_writer(path);
    writer->write(events);
    writer->close();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) *
                          static_cast<std::int64_t>(events.size()));
  std::filesystem::remove(path);
}
BENCHMARK(BM_Write_RpgText)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
