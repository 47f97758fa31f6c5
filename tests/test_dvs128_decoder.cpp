// The DVS128 USB word decoder (pure). Expected events are written out by
// hand from the wire format in ../shared/reference/dvs128-usb.md.
#include <gtest/gtest.h>

#include <cstdint>
#include <set>
#include <vector>

#include "evlife/io/dvs128_biases.h"
#include "evlife/io/dvs128_decoder.h"

namespace {

using evlife::Event;
using evlife::io::Dvs128Decoder;

std::vector<std::uint8_t> le(std::initializer_list<std::uint32_t> words) {
  std::vector<std::uint8_t> b;
  for (auto w : words) {
    for (int i = 0; i < 4; ++i) b.push_back(static_cast<std::uint8_t>(w >> (8 * i)));
  }
  return b;
}

// address: y << 8 | x << 1 | pol ; timestamp in bits 16..29.
constexpr std::uint32_t word(std::uint32_t raw_x, std::uint32_t raw_y, std::uint32_t pol,
                             std::uint32_t ts) {
  return (raw_y << 8) | (raw_x << 1) | pol | (ts << 16);
}

std::vector<Event> decode_all(Dvs128Decoder& d, const std::vector<std::uint8_t>& bytes) {
  std::vector<Event> out(bytes.size() / 4 + 1);
  const auto r = d.decode(bytes, out);
  EXPECT_EQ(r.bytes_consumed, bytes.size());
  out.resize(r.events_written);
  return out;
}

TEST(Dvs128Decoder, FlipsBothAxesAndMapsPolarityBitZeroToOn) {
  Dvs128Decoder d;
  // Raw (0,0) is the sensor's bottom-right in our convention: x = 127 - 0, y = 127 - 0.
  const auto ev = decode_all(d, le({word(0, 0, 0, 7), word(127, 127, 1, 8), word(3, 100, 1, 9)}));
  ASSERT_EQ(ev.size(), 3u);
  EXPECT_EQ(ev[0].x, 127);
  EXPECT_EQ(ev[0].y, 127);
  EXPECT_EQ(ev[0].p, 1);
  EXPECT_EQ(ev[0].t_us, 7);
  EXPECT_EQ(ev[1].x, 0);
  EXPECT_EQ(ev[1].y, 0);
  EXPECT_EQ(ev[1].p, -1);
  EXPECT_EQ(ev[2].x, 124);
  EXPECT_EQ(ev[2].y, 27);
  EXPECT_EQ(ev[2].p, -1);
  EXPECT_EQ(ev[2].t_us, 9);
}

TEST(Dvs128Decoder, EveryAddressMapsToADistinctPixelAndPolarity) {
  Dvs128Decoder d;
  std::set<int> seen;
  for (std::uint32_t y = 0; y < 128; ++y) {
    for (std::uint32_t x = 0; x < 128; ++x) {
      for (std::uint32_t p = 0; p < 2; ++p) {
        const auto ev = decode_all(d, le({word(x, y, p, 1)}));
        ASSERT_EQ(ev.size(), 1u);
        ASSERT_EQ(ev[0].x, 127 - static_cast<int>(x));
        ASSERT_EQ(ev[0].y, 127 - static_cast<int>(y));
        seen.insert((ev[0].y * 128 + ev[0].x) * 2 + (ev[0].p > 0 ? 1 : 0));
      }
    }
  }
  EXPECT_EQ(seen.size(), 128u * 128u * 2u);
}

TEST(Dvs128Decoder, WrapsAddSixteenThousandThreeHundredEightyFourMicroseconds) {
  Dvs128Decoder d;
  const auto ev = decode_all(d, le({word(1, 1, 0, 0x3FFF), 0x80000000u, word(1, 1, 0, 2),
                                    0x80000000u, 0x80000000u, word(1, 1, 0, 0)}));
  ASSERT_EQ(ev.size(), 3u);
  EXPECT_EQ(ev[0].t_us, 16383);
  EXPECT_EQ(ev[1].t_us, 16384 + 2);
  EXPECT_EQ(ev[2].t_us, 3 * 16384);
  EXPECT_EQ(d.counters().wraps, 3u);
}

TEST(Dvs128Decoder, WrapIsTestedBeforeReset) {
  Dvs128Decoder d;
  const auto ev = decode_all(d, le({word(1, 1, 0, 5), 0xC0000000u, word(1, 1, 0, 5)}));
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[1].t_us, 16384 + 5);
  EXPECT_EQ(d.counters().wraps, 1u);
  EXPECT_EQ(d.counters().resets, 0u);
}

TEST(Dvs128Decoder, ResetZeroesTheWrapOffsetAndTimeContinuesFromTheLastEvent) {
  Dvs128Decoder d;
  // Start of a run: reset before any event -> timestamps start at 0.
  auto ev = decode_all(d, le({0x40000000u, word(2, 2, 0, 10)}));
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].t_us, 10);
  // Mid-stream: 2 wraps, event at 32768 + 100; reset; device clock restarts.
  ev = decode_all(d, le({0x80000000u, 0x80000000u, word(2, 2, 0, 100), 0x40000000u,
                         word(2, 2, 0, 3), 0x80000000u, word(2, 2, 0, 1)}));
  ASSERT_EQ(ev.size(), 3u);
  EXPECT_EQ(ev[0].t_us, 32868);
  EXPECT_EQ(ev[1].t_us, 32868 + 3);          // offset zeroed, epoch = last event
  EXPECT_EQ(ev[2].t_us, 32868 + 16384 + 1);  // wraps count again from the reset
  EXPECT_EQ(d.counters().resets, 2u);
}

TEST(Dvs128Decoder, SyncWordsAreCountedNotEmitted) {
  Dvs128Decoder d;
  const auto ev = decode_all(d, le({0x00008000u | (5u << 16), word(1, 1, 0, 6), 0x0000FFFFu}));
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].t_us, 6);
  EXPECT_EQ(d.counters().sync_events, 2u);
  EXPECT_EQ(d.counters().pixel_events, 1u);
  EXPECT_EQ(d.counters().words, 3u);
}

TEST(Dvs128Decoder, WordsSplitAcrossTransfersAtAnyByte) {
  const auto bytes = le({word(1, 2, 0, 1), 0x80000000u, word(3, 4, 1, 2), word(5, 6, 0, 3)});
  Dvs128Decoder whole;
  const auto expected = decode_all(whole, bytes);
  ASSERT_EQ(expected.size(), 3u);
  for (std::size_t split = 0; split <= bytes.size(); ++split) {
    Dvs128Decoder d;
    std::vector<Event> got(8);
    const std::vector<std::uint8_t> a(bytes.begin(), bytes.begin() + static_cast<long>(split));
    const std::vector<std::uint8_t> b(bytes.begin() + static_cast<long>(split), bytes.end());
    const auto r1 = d.decode(a, got);
    EXPECT_EQ(r1.bytes_consumed, a.size());
    const auto r2 = d.decode(b, std::span<Event>(got).subspan(r1.events_written));
    EXPECT_EQ(r2.bytes_consumed, b.size());
    ASSERT_EQ(r1.events_written + r2.events_written, expected.size()) << "split " << split;
    for (std::size_t i = 0; i < expected.size(); ++i) {
      EXPECT_EQ(got[i].t_us, expected[i].t_us);
      EXPECT_EQ(got[i].x, expected[i].x);
    }
    EXPECT_EQ(d.pending_bytes(), 0u);
  }
}

TEST(Dvs128Decoder, StopsWhenTheOutputIsFullAndResumes) {
  Dvs128Decoder d;
  const auto bytes = le({word(1, 1, 0, 1), word(2, 1, 0, 2), 0x80000000u, word(3, 1, 0, 3)});
  std::vector<Event> out(2);
  const auto r1 = d.decode(bytes, out);
  EXPECT_EQ(r1.events_written, 2u);
  EXPECT_EQ(r1.bytes_consumed, 8u);
  const auto r2 = d.decode(std::span(bytes).subspan(r1.bytes_consumed), out);
  EXPECT_EQ(r2.events_written, 1u);
  EXPECT_EQ(r2.bytes_consumed, 8u);
  EXPECT_EQ(out[0].t_us, 16384 + 3);
  EXPECT_EQ(out[0].x, 124);
}

TEST(Dvs128Decoder, OlderWordsAreClampedAndCounted) {
  Dvs128Decoder d;
  const auto ev = decode_all(d, le({word(1, 1, 0, 500), word(1, 1, 0, 400)}));
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[1].t_us, 500);
  EXPECT_EQ(d.counters().time_regressions, 1u);
}

TEST(Dvs128Biases, DefaultsAreSentBigEndianInFirmwareOrder) {
  const auto b = evlife::io::Dvs128Biases{}.to_bytes();
  // cas 1992 = 0x0007C8, reqPd 16777215 = 0xFFFFFF, pr 217 = 0x0000D9.
  EXPECT_EQ(b[0], 0x00);
  EXPECT_EQ(b[1], 0x07);
  EXPECT_EQ(b[2], 0xC8);
  EXPECT_EQ(b[6], 0xFF);
  EXPECT_EQ(b[8], 0xFF);
  EXPECT_EQ(b[33], 0x00);
  EXPECT_EQ(b[35], 0xD9);
}

TEST(Dvs128Biases, ShippedBiasFileEqualsTheDefaults) {
  const auto file = evlife::io::Dvs128Biases::load_file(std::string(EVLIFE_SOURCE_DIR) +
                                                         "/config/dvs128_biases.yaml");
  EXPECT_EQ(file.values, evlife::io::Dvs128Biases{}.values);
}

// A directory opens as a stream that reads nothing: it would have sent the
// defaults without a word.
TEST(Dvs128Biases, ADirectoryIsNoBiasFile) {
  try {
    evlife::io::Dvs128Biases::load_file(EVLIFE_BINARY_DIR);
    FAIL() << "a directory accepted as a bias file";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(std::string(EVLIFE_BINARY_DIR) + ": a directory, not a DVS128 bias file"),
              std::string::npos)
        << e.what();
  }
}

TEST(Dvs128Biases, UnknownNameIsAnErrorNamingFileAndLine) {
  const std::string path = std::string(EVLIFE_BINARY_DIR) + "/test_dvs128_bad_biases.yaml";
  {
    std::FILE* f = std::fopen(path.c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs("cas: 1\ncasx: 2\n", f);
    std::fclose(f);
  }
  try {
    evlife::io::Dvs128Biases::load_file(path);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path + ":2: unknown bias 'casx'"), std::string::npos)
        << e.what();
  }
  std::remove(path.c_str());
}

}  // namespace
