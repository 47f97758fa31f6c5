#include "cut_stream.h"

#include <bzlib.h>
#include <lz4frame.h>

#include <array>
#include <cstddef>

namespace evlife::io::detail {

bool inflate_cut_bz2(std::span<const std::uint8_t> in, std::vector<std::uint8_t>& out, std::size_t max_bytes) {
  constexpr std::size_t kStreamHeaderBytes = 4;
  out.clear();
  bz_stream s{};
  if (BZ2_bzDecompressInit(&s, 0, 0) != BZ_OK) return !in.empty();
  std::array<char, 1 << 16> buffer{};
  s.next_in = const_cast<char*>(reinterpret_cast<const char*>(in.data()));  // bzlib's API: not written
  s.avail_in = static_cast<unsigned int>(in.size());
  int rc = BZ_OK;
  while (rc == BZ_OK && out.size() <= max_bytes) {
    s.next_out = buffer.data();
    s.avail_out = buffer.size();
    rc = BZ2_bzDecompress(&s);
    const std::size_t produced = buffer.size() - s.avail_out;
    out.insert(out.end(), buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(produced));
    if (produced == 0 && s.avail_in == 0) break;
  }
  BZ2_bzDecompressEnd(&s);
  return rc != BZ_STREAM_END && in.size() > kStreamHeaderBytes;
}

bool inflate_cut_lz4(std::span<const std::uint8_t> in, std::vector<std::uint8_t>& out, std::size_t max_bytes) {
  constexpr std::size_t kBlockHeaderBytes = 4;
  out.clear();
  LZ4F_dctx* ctx = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION))) return !in.empty();
  std::array<std::uint8_t, 1 << 16> buffer{};
  std::size_t at = 0;
  std::size_t hint = 1;
  while (out.size() <= max_bytes) {
    std::size_t out_len = buffer.size();
    std::size_t in_len = in.size() - at;
    hint = LZ4F_decompress(ctx, buffer.data(), &out_len, in.data() + at, &in_len, nullptr);
    if (LZ4F_isError(hint)) break;
    out.insert(out.end(), buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(out_len));
    at += in_len;
    if (hint == 0 || (out_len == 0 && in_len == 0)) break;  // the frame's end, or all there is
  }
  LZ4F_freeDecompressionContext(ctx);
  if (LZ4F_isError(hint)) return true;
  return hint != 0 && hint != kBlockHeaderBytes && !in.empty();
}

}  // namespace evlife::io::detail
