// libFuzzer target: the DVS128 USB word decoder. The first input byte picks
// how the rest is cut into transfers and how small the output buffers are;
// the stream decoded in those pieces must equal the stream decoded in one
// call (transfers need not be word aligned), and every event must be on the
// 128x128 sensor with polarity +-1 and time never going backwards.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <span>
#include <vector>

#include "evlife/io/dvs128_decoder.h"

namespace {

void fail(const char* what) {
  std::fprintf(stderr, "evlife fuzz: DVS128 decoder contract broken: %s\n", what);
  std::abort();
}

bool same(const evlife::Event& a, const evlife::Event& b) {
  return a.t_us == b.t_us && a.x == b.x && a.y == b.y && a.p == b.p;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using evlife::Event;
  using evlife::io::Dvs128Decoder;
  if (size < 1) return 0;
  const std::uint8_t shape = data[0];
  const std::span<const std::uint8_t> words(data + 1, size - 1);

  // Reference: one call, room for every word.
  Dvs128Decoder whole;
  std::vector<Event> expected(words.size() / 4 + 1);
  const auto r = whole.decode(words, expected);
  if (r.bytes_consumed != words.size()) fail("one call did not consume all bytes");
  if (whole.pending_bytes() != words.size() % 4) fail("pending bytes != size % 4");
  if (whole.counters().words != words.size() / 4) fail("word count");
  if (whole.counters().pixel_events != r.events_written) fail("pixel_events != events written");
  expected.resize(r.events_written);
  std::int64_t last_t_us = 0;
  for (const Event& e : expected) {
    if (e.x >= 128 || e.y >= 128) fail("event outside 128x128");
    if (e.p != 1 && e.p != -1) fail("polarity not +1/-1");
    if (e.t_us < last_t_us) fail("time going backwards");
    last_t_us = e.t_us;
  }

  // Pieces: transfer sizes 1..16 bytes, output buffers of 1..8 events.
  const std::size_t transfer = 1 + (shape & 0x0F);
  const std::size_t out_size = 1 + ((shape >> 4) & 0x07);
  Dvs128Decoder pieces;
  std::vector<Event> got;
  std::vector<Event> out(out_size);
  for (std::size_t pos = 0; pos < words.size();) {
    auto chunk = words.subspan(pos, std::min(transfer, words.size() - pos));
    pos += chunk.size();
    while (!chunk.empty()) {
      const auto step = pieces.decode(chunk, out);
      if (step.bytes_consumed > chunk.size() || step.events_written > out.size()) fail("overrun");
      if (step.bytes_consumed == 0 && step.events_written == 0) fail("no progress");
      got.insert(got.end(), out.begin(), out.begin() + static_cast<std::ptrdiff_t>(step.events_written));
      chunk = chunk.subspan(step.bytes_consumed);
    }
  }
  if (got.size() != expected.size()) fail("piecewise decode emitted a different event count");
  for (std::size_t i = 0; i < got.size(); ++i) {
    if (!same(got[i], expected[i])) fail("piecewise decode differs from one-call decode");
  }
  if (std::memcmp(&pieces.counters(), &whole.counters(), sizeof(whole.counters())) != 0)
    fail("counters differ between piecewise and one-call decode");
  return 0;
}
