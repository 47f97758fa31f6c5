// Prints a digest of what the estimator and the engine's pipeline make of
// each recording given: one line per (recording, path), FNV-1a 64 over every
// output field's bits. .ci/cross-aarch64 runs it from the x86-64 and the
// aarch64 (qemu) builds and compares the lines: the results must be equal bit
// for bit on both architectures (the SIMD of window_samples.h is SSE on one,
// NEON on the other). The digest is computed at CI time by both builds; no
// expected value is stored anywhere.
//
//   evlife_output_digest FILE...   (exit 1 naming the file on a read error)
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "evlife/algo/lifetime_estimator.h"
#include "evlife/engine/augmented_sink.h"
#include "evlife/engine/pipeline.h"
#include "evlife/engine/replay_source.h"
#include "evlife/io/event_reader.h"
#include "evlife/io/sensor_size_from_data.h"

namespace {

struct Digest {
  std::uint64_t h = 1469598103934665603ull;
  std::uint64_t events = 0, noise = 0;
  void bytes(const void* p, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
  }
  void add(const evlife::AugmentedEvent& a) {
    // Field by field: no padding bytes can enter the digest.
    bytes(&a.event.t_us, sizeof a.event.t_us);
    bytes(&a.event.x, sizeof a.event.x);
    bytes(&a.event.y, sizeof a.event.y);
    bytes(&a.event.p, sizeof a.event.p);
    bytes(&a.lifetime_us, sizeof a.lifetime_us);
    bytes(&a.vx_px_s, sizeof a.vx_px_s);
    bytes(&a.vy_px_s, sizeof a.vy_px_s);
    bytes(&a.prediction_error_us, sizeof a.prediction_error_us);
    ++events;
    noise += a.is_noise() ? 1 : 0;
  }
  void print(const std::string& file, const char* path) const {
    std::printf("%s %s events=%llu noise=%llu fnv1a64=%016llx\n", file.c_str(), path,
                static_cast<unsigned long long>(events), static_cast<unsigned long long>(noise),
                static_cast<unsigned long long>(h));
  }
};

std::vector<evlife::Event> read_all(evlife::io::EventReader& reader) {
  std::vector<evlife::Event> events;
  std::vector<evlife::Event> chunk(1 << 16);
  for (;;) {
    const std::size_t n = reader.read(chunk);
    if (n == 0) break;
    events.insert(events.end(), chunk.begin(), chunk.begin() + static_cast<std::ptrdiff_t>(n));
  }
  return events;
}

void digest_file(const std::string& file) {
  auto reader = evlife::io::open_event_reader(file);
  std::vector<evlife::Event> events = read_all(*reader);
  // The sensor as `evlife process` and test_real_recordings find it: the
  // digests then stand for that suite's default-option runs (.ci/cross-aarch64).
  const evlife::SensorSize sensor = evlife::io::resolve_sensor_size(file, std::nullopt).size;
  evlife::LifetimeOptions options;
  options.sensor = sensor;

  // The bare estimator, one event at a time.
  evlife::LifetimeEstimator estimator(options);
  Digest bare;
  for (const auto& e : events) bare.add(estimator.process(e));
  bare.print(file, "estimator");

  // The engine's stages without threads: 2 workers, 2x2 tiles per polarity.
  evlife::engine::EngineOptions engine_options;
  engine_options.lifetime = options;
  engine_options.workers = 2;
  engine_options.tiles_x = 2;
  engine_options.tiles_y = 2;
  engine_options.stats_period_s = 0.0;
  Digest piped;
  evlife::engine::CallbackSink sink([&](std::span<const evlife::AugmentedEvent> s) {
    for (const auto& a : s) piped.add(a);
  });
  evlife::engine::ReplaySource source(events, sensor);
  evlife::engine::Pipeline pipeline(source, &sink, engine_options);
  pipeline.run_inline();
  piped.print(file, "pipeline-2x2-tiles");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: evlife_output_digest FILE...\n");
    return 2;
  }
  for (int i = 1; i < argc; ++i) {
    try {
      digest_file(argv[i]);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "evlife_output_digest: %s: %s\n", argv[i], e.what());
      return 1;
    }
  }
  return 0;
}
