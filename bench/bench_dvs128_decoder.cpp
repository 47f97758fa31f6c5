// Cost of decoding DVS128 USB event words, per event (items = pixel events).
// Input: one libcaer-sized 4096-byte transfer (1024 words) decoded over and
// over; the Arg is the number of pixel events between two wrap words.
//   ./bench/bench_dvs128_decoder
#include <benchmark/benchmark.h>

#include <cstdint>
#include <vector>

#include "evlife/io/dvs128_decoder.h"

namespace {

std::vector<std::uint8_t> transfer(int events_per_wrap) {
  std::vector<std::uint8_t> bytes;
  std::uint32_t ts = 0;
  int since_wrap = 0;
  for (int w = 0; w < 1024; ++w) {
    std::uint32_t word;
    if (events_per_wrap > 0 && since_wrap == events_per_wrap) {
      word = 0x80000000u;
      since_wrap = 0;
    } else {
      const std::uint32_t x = static_cast<std::uint32_t>(w * 37) % 128;
      const std::uint32_t y = static_cast<std::uint32_t>(w * 11) % 128;
      ts = (ts + 3) & 0x3FFF;
      word = (y << 8) | (x << 1) | static_cast<std::uint32_t>(w & 1) | (ts << 16);
      ++since_wrap;
    }
    for (int i = 0; i < 4; ++i) bytes.push_back(static_cast<std::uint8_t>(word >> (8 * i)));
  }
  return bytes;
}

void BM_Dvs128Decode(benchmark::State& state) {
  const auto bytes = transfer(static_cast<int>(state.range(0)));
  std::vector<evlife::Event> out(1024);
  evlife::io::Dvs128Decoder decoder;
  std::uint64_t events = 0;
  for (auto _ : state) {
    (void)_;  // clang-analyzer: the loop variable is only a counter
    const auto r = decoder.decode(bytes, out);
    benchmark::DoNotOptimize(out.data());
    events += r.events_written;
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(events));
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) *
                          static_cast<std::int64_t>(bytes.size()));
}
// 0 = no wraps (pure pixel words); 64 = a wrap word every 64 events (dense).
BENCHMARK(BM_Dvs128Decode)->Arg(0)->Arg(64);

}  // namespace

BENCHMARK_MAIN();
