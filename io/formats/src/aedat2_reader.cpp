// jAER AEDAT 2.0 from a DVS128: `#!AER-DAT2.0` and `#` header lines (CRLF),
// then per event a big-endian u32 address and a big-endian u32 timestamp (µs).
// DVS128 address (jAER DVS128.Extractor): bit 0 polarity (raw 0 = ON), bits
// 1-7 raw x, bits 8-14 raw y, bit 15 special/external event. jAER flips x
// (x = 127 - raw x) and keeps y with origin bottom-left; evlife's origin is
// top-left (as libcaer over USB), so both axes are flipped here:
//   x = 127 - ((a >> 1) & 0x7F),  y = 127 - ((a >> 8) & 0x7F).
#include <algorithm>
#include <cstring>
#include <vector>

#include "input_file.h"
#include "reader_registry.h"

namespace evlife::io::detail {
namespace {

constexpr std::string_view kMagic = "#!AER-DAT2.0";
constexpr std::size_t kRecordBytes = 8;
constexpr std::size_t kChunkRecords = 1 << 16;
constexpr int kSensorSide = 128;

std::uint32_t load_be32(const unsigned char* p) noexcept {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) |
         std::uint32_t{p[3]};
}

class Aedat2Reader final : public EventReader {
 public:
  explicit Aedat2Reader(const std::string& path) : file_(path) {
    parse_header();
    buffer_.resize(kChunkRecords * kRecordBytes);
  }

  std::size_t read(std::span<Event> out) override {
    if (pending_) throw *pending_;
    batch_first_index_ = next_index_;
    batch_first_offset_ = offset_;
    specials_in_batch_.clear();
    std::size_t n = 0;
    while (n < out.size()) {
      if (buffer_pos_ + kRecordBytes > buffer_end_ && !refill()) break;
      const auto* bytes = reinterpret_cast<const unsigned char*>(buffer_.data());
      // Decode straight from the buffer: whole records only.
      const std::size_t records =
          std::min((buffer_end_ - buffer_pos_) / kRecordBytes, out.size() - n);
      for (std::size_t r = 0; r < records; ++r) {
        const unsigned char* rec = bytes + buffer_pos_;
        const std::uint32_t address = load_be32(rec);
        const std::uint32_t ts = load_be32(rec + 4);
        if ((address >> 16) != 0) {  // a DVS128 never sets these bits
          pending_.emplace(file_.path(), static_cast<std::int64_t>(offset_),
                           static_cast<std::int64_t>(next_index_),
                           "corrupt AEDAT 2.0 record: address 0x" + hex(address) +
                               " has bits above 15 set (not a DVS128 address)");
          break;
        }
        buffer_pos_ += kRecordBytes;
        offset_ += kRecordBytes;
        // Unwrap the 32-bit µs clock (wraps every 71.6 min): a jump back by more
        // than half the range is a wrap; smaller steps back are kept as they
        // are so that the checked reader reports them.
        if (ts < last_raw_ts_ && last_raw_ts_ - ts > 0x80000000u) wrap_us_ += std::int64_t{1} << 32;
        last_raw_ts_ = ts;
        if (address & 0x8000u) {
          ++skipped_;
          specials_in_batch_.push_back(next_index_);
          continue;
        }
        Event& e = out[n++];
        e.t_us = wrap_us_ + ts;
        e.x = static_cast<std::uint16_t>(kSensorSide - 1 - ((address >> 1) & 0x7Fu));
        e.y = static_cast<std::uint16_t>(kSensorSide - 1 - ((address >> 8) & 0x7Fu));
        e.p = (address & 1u) ? std::int8_t{-1} : std::int8_t{1};
        ++next_index_;
        if (n == out.size()) break;
      }
      if (pending_) break;
    }
    if (n == 0 && pending_) throw *pending_;
    return n;
  }

  std::optional<SensorSize> sensor_size() const override { return SensorSize{128, 128}; }
  std::string_view format_name() const override { return "aedat2"; }
  const std::string& path() const override { return file_.path(); }
  std::uint64_t skipped_record_count() const override { return skipped_; }
  std::uint64_t bytes_consumed() const override { return offset_; }

  std::int64_t byte_offset_of_event(std::int64_t event_index) const override {
    if (event_index < static_cast<std::int64_t>(batch_first_index_) ||
        event_index > static_cast<std::int64_t>(next_index_))
      return -1;
    const auto index = static_cast<std::uint64_t>(event_index);
    // Records before it in this batch = events before it + specials skipped before it.
    const auto specials = static_cast<std::uint64_t>(
        std::upper_bound(specials_in_batch_.begin(), specials_in_batch_.end(), index) -
        specials_in_batch_.begin());
    return static_cast<std::int64_t>(batch_first_offset_ +
                                     (index - batch_first_index_ + specials) * kRecordBytes);
  }

 private:
  static std::string hex(std::uint32_t v) {
    char text[9];
    static constexpr char digits[] = "0123456789abcdef";
    for (int i = 7; i >= 0; --i, v >>= 4) text[i] = digits[v & 0xF];
    text[8] = '\0';
    return text;
  }

  // Header: lines starting with '#'; the first one is the magic. The chip line
  // ("# AEChip: ...") must name a DVS128 (other chips pack addresses otherwise).
  void parse_header() {
    std::vector<std::byte> chunk(1 << 16);
    std::string line;
    std::uint64_t pos = 0;
    bool at_line_start = true;
    bool first_line = true;
    for (;;) {
      const std::size_t got = file_.read_at(pos, chunk);
      if (got == 0) break;
      std::size_t i = 0;
      for (; i < got; ++i) {
        const char c = static_cast<char>(chunk[i]);
        if (at_line_start) {
          if (c != '#') break;  // header ends at the first line not starting with '#'
          at_line_start = false;
          line.clear();
        }
        if (c == '\n') {
          check_header_line(line, first_line, pos + i);
          first_line = false;
          at_line_start = true;
        } else if (line.size() < 4096) {
          line.push_back(c);
        }
      }
      pos += i;
      if (i < got) break;
    }
    if (!at_line_start)
      throw ReadError(file_.path(), static_cast<std::int64_t>(pos), -1,
                      "truncated AEDAT 2.0 header (no end of line)");
    if (first_line)
      throw ReadError(file_.path(), 0, -1, "not an AEDAT 2.0 file (no '#!AER-DAT2.0' line)");
    header_bytes_ = pos;
    offset_ = pos;
  }

  void check_header_line(std::string line, bool first_line, std::uint64_t end) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (first_line && line.rfind(kMagic, 0) != 0)
      throw ReadError(file_.path(), 0, -1, "not an AEDAT 2.0 file (first line '" + line + "')");
    constexpr std::string_view kChip = "# AEChip:";
    if (line.rfind(kChip, 0) == 0 && line.find("DVS128") == std::string::npos &&
        line.find("Tmpdiff128") == std::string::npos)
      throw ReadError(file_.path(), static_cast<std::int64_t>(end), -1,
                      "AEDAT 2.0 from chip '" + line.substr(kChip.size()) +
                          "': only the DVS128 address layout is supported");
  }

  // Moves the partial record to the front and reads more. False at end of
  // file; a trailing partial record becomes a pending truncation error.
  bool refill() {
    const std::size_t leftover = buffer_end_ - buffer_pos_;
    std::memmove(buffer_.data(), buffer_.data() + buffer_pos_, leftover);
    const std::size_t got = file_.read_at(
        offset_ + leftover, std::span(buffer_).subspan(leftover));
    buffer_pos_ = 0;
    buffer_end_ = leftover + got;
    if (buffer_end_ >= kRecordBytes) return true;
    if (buffer_end_ > 0 && !pending_)
      pending_.emplace(file_.path(), static_cast<std::int64_t>(offset_),
                       static_cast<std::int64_t>(next_index_),
                       "truncated AEDAT 2.0 file: " + std::to_string(buffer_end_) +
                           " trailing bytes, a record is 8");
    return false;
  }

  InputFile file_;
  std::vector<std::byte> buffer_;
  std::size_t buffer_pos_ = 0;
  std::size_t buffer_end_ = 0;
  std::uint64_t header_bytes_ = 0;
  std::uint64_t offset_ = 0;      // file offset of buffer_[buffer_pos_]
  std::uint64_t next_index_ = 0;  // index of the next event delivered
  std::uint64_t skipped_ = 0;
  std::uint32_t last_raw_ts_ = 0;
  std::int64_t wrap_us_ = 0;
  std::uint64_t batch_first_index_ = 0;
  std::uint64_t batch_first_offset_ = 0;
  std::vector<std::uint64_t> specials_in_batch_;  // event index following each skipped special
  std::optional<ReadError> pending_;
};

SniffResult sniff_aedat2(std::span<const std::byte> head, std::string_view path) {
  if (head.size() >= kMagic.size() &&
      std::memcmp(head.data(), kMagic.data(), kMagic.size()) == 0)
    return SniffResult::by_content;
  (void)path;  // .aedat is shared by AEDAT 2/3/4: never sniff by extension alone
  return SniffResult::no;
}

std::unique_ptr<EventReader> open_aedat2(const std::string& path) {
  return std::make_unique<Aedat2Reader>(path);
}

}  // namespace

const ReaderFormat aedat2_format{"aedat2",
                                 "jAER AEDAT 2.0 from a DVS128 ('#!AER-DAT2.0' header, "
                                 "big-endian u32 address + u32 timestamp in us)",
                                 &sniff_aedat2, &open_aedat2};

}  // namespace evlife::io::detail
