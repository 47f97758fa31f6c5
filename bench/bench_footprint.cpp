// Memory each part of evlife needs per sensor size, measured (not computed):
// the heap bytes in use (glibc mallinfo2: arena + mmapped chunks) before and
// after constructing the part, and the resident-set growth once it exists.
// All memory of these parts is allocated at construction (nothing grows per
// event), so this is their footprint for a whole run. Then the sizes of any
// files given (the static libraries, the evlife tool; README: Footprint).
//
//   build/bench/bench_footprint [FILE...]
#include <malloc.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "evlife/algo/lifetime_estimator.h"
#include "evlife/engine/pipeline.h"
#include "evlife/engine/replay_source.h"
#include "evlife/algo/active_event_map.h"

namespace {

long long heap_in_use() {
  const struct mallinfo2 m = mallinfo2();
  return static_cast<long long>(m.uordblks) + static_cast<long long>(m.hblkhd);
}

long long rss_bytes() {
  std::ifstream statm("/proc/self/statm");
  long long pages_total = 0, pages_resident = 0;
  statm >> pages_total >> pages_resident;
  return pages_resident * sysconf(_SC_PAGESIZE);
}

struct Measured {
  long long heap = 0, rss = 0;
};

// Constructs T(args...), measures, destroys it.
template <typename Make>
Measured measure(Make make) {
  malloc_trim(0);
  const long long heap0 = heap_in_use(), rss0 = rss_bytes();
  auto part = make();
  Measured m{heap_in_use() - heap0, rss_bytes() - rss0};
  part.reset();
  return m;
}

double mib(long long bytes) { return static_cast<double>(bytes) / (1024.0 * 1024.0); }

}  // namespace

int main(int argc, char** argv) {
  namespace ee = evlife::engine;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0) {
      std::printf("usage: bench_footprint [FILE...]\n\n"
                  "Prints a table of the memory the estimator, the engine (2 workers, default queues) and\n"
                  "the active-event map take per sensor size: the heap bytes their construction allocates\n"
                  "(glibc mallinfo2) and the resident-set growth it causes. Then the size of each FILE\n"
                  "(static libraries, the evlife tool). The README's Footprint section quotes it.\n");
      return 0;
    }
  }
  // A fixed threshold: glibc raises it after a large free, and the parts
  // measured later would then come from the arena with other slack.
  mallopt(M_MMAP_THRESHOLD, 128 * 1024);
  const evlife::SensorSize sizes[] = {{128, 128}, {346, 260}, {640, 480}, {1280, 720}};
  std::printf("| sensor | estimator state, heap / resident | engine, 2 workers (default queues), heap / resident | "
              "of which pools and queues | active-event map | total heap, engine + map |\n|---|---|---|---|---|---|\n");
  for (const evlife::SensorSize s : sizes) {
    evlife::LifetimeOptions lo;
    lo.sensor = s;
    const Measured est = measure([&] { return std::make_unique<evlife::LifetimeEstimator>(lo); });
    ee::EngineOptions eo;  // defaults: 2 workers, 1x1 tiles, 64 batches x 1024 events per worker
    eo.lifetime = lo;
    eo.stats_period_s = 0.0;
    static const std::vector<evlife::Event> none;
    ee::ReplaySource source(none, s);
    const Measured pipe = measure([&] { return std::make_unique<ee::Pipeline>(source, nullptr, eo); });
    const Measured map = measure([&] { return std::make_unique<evlife::ActiveEventMap>(s); });
    const long long pools = pipe.heap - eo.workers * est.heap;
    std::printf("| %dx%d | %.2f / %.2f MiB | %.2f / %.2f MiB | %.2f MiB | %.2f MiB | %.2f MiB |\n", s.width,
                s.height, mib(est.heap), mib(est.rss), mib(pipe.heap), mib(pipe.rss), mib(pools), mib(map.heap),
                mib(pipe.heap + map.heap));
  }
  if (argc > 1) std::printf("\n| file | bytes | KiB |\n|---|---|---|\n");
  for (int i = 1; i < argc; ++i) {
    std::error_code ec;
    const auto bytes = std::filesystem::file_size(argv[i], ec);
    if (ec) {
      std::fprintf(stderr, "bench_footprint: %s: %s\n", argv[i], ec.message().c_str());
      return 1;
    }
    std::printf("| %s | %llu | %.0f |\n", argv[i], static_cast<unsigned long long>(bytes),
                static_cast<double>(bytes) / 1024.0);
  }
  return 0;
}
