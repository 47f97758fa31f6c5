// jAER AEDAT 2.0: `#!AER-DAT2.0` and `#` header lines (CRLF), then per
// record a big-endian u32 address and a big-endian u32 timestamp (µs). The
// `# AEChip: <java class>` line selects the address layout and the sensor
// (table in aedat2_chips.cpp); without it the file is a DVS128's, unless v2e
// wrote it (its `created by AEDat2Output in v2e` line, no AEChip line): then a
// DAVIS346's or, where every event lies within 240 x 180 raw pixels, a
// DAVIS240's — the two sensors v2e's AEDAT 2.0 writer knows, in the DAVIS
// layout, flipped as jAER's (a pass over the addresses guesses which, said so
// by sensor_size_note(); ReaderOptions::sensor, one of the two, decides).
//
// DVS128 (jAER DVS128.Extractor): bit 0 polarity (raw 0 = ON), bits 1-7 raw
// x, bits 8-14 raw y, bit 15 external input event.
//
// DAVIS (jAER eu.seebetter.ini.chips.DavisChip constants, decoded as
// davis.DavisBaseCamera.DavisEventExtractor.extractPacket does;
// github.com/SensorsINI/jaer): bit 31 set = not a DVS event: with bits 10-11
// both set an IMU word (7 consecutive words make one IMU sample: code in bits
// 28-30, 16-bit value in bits 12-27), otherwise an APS ADC sample (x 12-21,
// y 22-30, read cycle 10-11, value 0-9). Bit 31 clear: bits 10-11 = 01 is an
// external input event (trigger); else a DVS event with y in bits 22-30, x in
// bits 12-21, polarity in bit 11 (1 = ON); bits 0-9 are zero.
//
// Orientation: jAER displays x = W-1 - raw x and y = raw y with the origin at
// the bottom left (its USB code packs raw y = H-1 - row, raw x = W-1 - column
// of the sensor's readout, whose row 0 is the top). evlife's origin is the top
// left (as libcaer over USB), so both layouts flip both axes:
//   x = W-1 - raw x,  y = H-1 - raw y.
// APS samples, IMU words and external events are skipped and counted per kind
// (external events are the triggers), never mixed into the events.
#include <algorithm>
#include <array>
#include <cstring>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "aedat2_chips.h"
#include "input_file.h"
#include "reader_registry.h"
#include "skipped_kinds.h"
#include "wrapping_counter.h"

namespace evlife::io::detail {
namespace {

constexpr std::string_view kAedat2Magic = "#!AER-DAT2.0";
constexpr std::size_t kRecordBytes = 8;
constexpr std::size_t kChunkRecords = 1 << 16;

enum Skipped : std::size_t { kExternal, kApsSample, kImuWord, kSkippedKinds };
constexpr std::array<std::string_view, kSkippedKinds> kAedat2SkippedNames{"external", "aps-sample", "imu-word"};

constexpr std::uint32_t kDavisNotDvs = 0x80000000u;
constexpr std::uint32_t kDavisImu = 0x80000C00u;
constexpr std::uint32_t kDavisTypeMask = 0x00000C00u;
constexpr std::uint32_t kDavisExternal = 0x00000400u;
// A DAVIS DVS event's raw x (bits 12-21) and raw y (bits 22-30).
constexpr std::uint32_t davis_raw_x(std::uint32_t address) noexcept { return (address >> 12) & 0x3FFu; }
constexpr std::uint32_t davis_raw_y(std::uint32_t address) noexcept { return (address >> 22) & 0x1FFu; }

std::uint32_t load_be32(const unsigned char* p) noexcept {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) |
         std::uint32_t{p[3]};
}

std::string hex_address(std::uint32_t v) {
  char text[9];
  static constexpr char digits[] = "0123456789abcdef";
  for (int i = 7; i >= 0; --i, v >>= 4) text[i] = digits[v & 0xF];
  text[8] = '\0';
  return text;
}

// The two sensors v2e's AEDAT 2.0 writer knows (v2ecore/output/aedat2_output.py), smaller first.
constexpr const char* kV2eChips[] = {"DAVIS240", "Davis346"};

class Aedat2Reader final : public EventReader {
 public:
  Aedat2Reader(const std::string& path, std::optional<SensorSize> user_sensor)
      : file_(path), chip_(&default_aedat2_chip()) {
    parse_header();
    buffer_.resize(kChunkRecords * kRecordBytes);
    if (written_by_v2e_ && !chip_line_) {
      // The user's sensor, when it is one of v2e's two, decides; else the guess.
      for (const char* name : kV2eChips) {
        const Aedat2Chip* chip = find_aedat2_chip(name);
        if (user_sensor && *user_sensor == SensorSize{chip->width, chip->height}) {
          chip_ = chip;
          sensor_from_user_ = true;
        }
      }
      if (!sensor_from_user_) chip_ = &v2e_chip();
    }
  }

  std::size_t read(std::span<Event> out) override {
    if (pending_) throw *pending_;
    batch_first_index_ = next_index_;
    batch_first_offset_ = offset_;
    skips_in_batch_.clear();
    skips_in_batch_.reserve(out.size() + 1);  // allocates only when batches grow
    skipped_in_batch_ = 0;
    std::size_t n = 0;
    while (n < out.size()) {
      if (buffer_pos_ + kRecordBytes > buffer_end_ && !refill()) break;
      n = chip_->layout == Aedat2Layout::davis ? decode<Aedat2Layout::davis>(out, n)
                                               : decode<Aedat2Layout::dvs128>(out, n);
      if (pending_) break;
    }
    if (n == 0 && pending_) throw *pending_;
    return n;
  }

  std::optional<SensorSize> sensor_size() const override {
    return SensorSize{chip_->width, chip_->height};
  }
  std::string sensor_size_note() const override {
    if (!written_by_v2e_ || chip_line_) return {};
    if (sensor_from_user_) return "given: v2e names no sensor";
    return chip_->width == 240 ? "guessed: v2e names no sensor, and no event lies beyond 240x180 (a DAVIS346 "
                                 "recording whose events all do would read shifted)"
                               : "guessed: v2e names no sensor, and events lie beyond 240x180";
  }
  std::string_view format_name() const override { return "aedat2"; }
  std::string clock_wrap_note() const override { return decltype(clock_)::wrap_note(1); }
  const std::string& path() const override { return file_.path(); }
  std::uint64_t skipped_record_count() const override { return skipped_.total(); }
  std::uint64_t trigger_count() const override { return skipped_.count(kExternal); }
  std::vector<SkippedKindCount> skipped_record_kinds() const override { return skipped_.seen(); }
  std::uint64_t bytes_consumed() const override { return offset_; }

  std::int64_t byte_offset_of_event(std::int64_t event_index) const override {
    if (event_index < static_cast<std::int64_t>(batch_first_index_) ||
        event_index > static_cast<std::int64_t>(next_index_))
      return -1;
    const auto index = static_cast<std::uint64_t>(event_index);
    // Records before it in this batch = events before it + records skipped before it.
    const auto after = std::upper_bound(
        skips_in_batch_.begin(), skips_in_batch_.end(), index,
        [](std::uint64_t i, const std::pair<std::uint64_t, std::uint64_t>& s) { return i < s.first; });
    const std::uint64_t skipped = after == skips_in_batch_.begin() ? 0 : std::prev(after)->second;
    return static_cast<std::int64_t>(batch_first_offset_ +
                                     (index - batch_first_index_ + skipped) * kRecordBytes);
  }

 private:
  /// Decodes the whole records in the buffer into out[n...]; returns the new n.
  template <Aedat2Layout L>
  std::size_t decode(std::span<Event> out, std::size_t n) {
    const auto* bytes = reinterpret_cast<const unsigned char*>(buffer_.data());
    const std::size_t records = (buffer_end_ - buffer_pos_) / kRecordBytes;
    const auto width = static_cast<std::uint32_t>(chip_->width);
    const auto height = static_cast<std::uint32_t>(chip_->height);
    for (std::size_t r = 0; r < records && n < out.size(); ++r) {
      const unsigned char* rec = bytes + buffer_pos_;
      const std::uint32_t address = load_be32(rec);
      const std::uint32_t ts = load_be32(rec + 4);
      std::uint32_t raw_x = 0, raw_y = 0;
      bool on = false;
      std::size_t skip = kSkippedKinds;
      if constexpr (L == Aedat2Layout::dvs128) {
        if ((address >> 16) != 0)  // a DVS128 never sets these bits
          return corrupt(n, address, "has bits above 15 set (not a DVS128 address)");
        if (address & 0x8000u) skip = kExternal;
        raw_x = (address >> 1) & 0x7Fu;
        raw_y = (address >> 8) & 0x7Fu;
        on = (address & 1u) == 0;
      } else {
        if ((address & kDavisImu) == kDavisImu) {
          skip = kImuWord;
        } else if (address & kDavisNotDvs) {
          skip = kApsSample;
        } else if ((address & kDavisTypeMask) == kDavisExternal) {
          skip = kExternal;
        } else {
          if ((address & 0x3FFu) != 0)
            return corrupt(n, address, "is a DVS event with bits 0-9 set (not a DAVIS address)");
          raw_x = davis_raw_x(address);
          raw_y = davis_raw_y(address);
          if (raw_x >= width || raw_y >= height)
            return corrupt(n, address,
                           "is a DVS event at raw x " + std::to_string(raw_x) + ", y " + std::to_string(raw_y) +
                               ", outside the " + std::to_string(width) + "x" + std::to_string(height) + " " +
                               std::string(chip_->class_prefix) + " sensor");
          on = (address & 0x800u) != 0;
        }
      }
      buffer_pos_ += kRecordBytes;
      offset_ += kRecordBytes;
      // The 32-bit µs clock wraps every 71.6 min; steps back are kept so
      // that the checked reader reports them.
      const std::int64_t t_us = clock_.unwrap(ts);
      if (skip != kSkippedKinds) {
        skipped_.add(skip);
        note_skip();
        continue;
      }
      out[n++] = Event{t_us, static_cast<std::uint16_t>(width - 1 - raw_x),
                       static_cast<std::uint16_t>(height - 1 - raw_y), on ? std::int8_t{1} : std::int8_t{-1}};
      ++next_index_;
    }
    return n;
  }

  std::size_t corrupt(std::size_t n, std::uint32_t address, const std::string& what) {
    pending_.emplace(file_.path(), static_cast<std::int64_t>(offset_), static_cast<std::int64_t>(next_index_),
                     "corrupt AEDAT 2.0 record: address 0x" + hex_address(address) + " " + what);
    return n;
  }

  /// Remembers that a record was skipped before event next_index_ (for
  /// byte_offset_of_event): one entry per event index, at most out.size() + 1.
  void note_skip() noexcept {
    ++skipped_in_batch_;
    if (!skips_in_batch_.empty() && skips_in_batch_.back().first == next_index_)
      skips_in_batch_.back().second = skipped_in_batch_;
    else
      skips_in_batch_.emplace_back(next_index_, skipped_in_batch_);
  }

  // Header: lines starting with '#'; the first one is the magic.
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
    if (!chip_line_ && davis_hardware_)
      throw ReadError(file_.path(), static_cast<std::int64_t>(pos), -1,
                      "AEDAT 2.0 from DAVIS hardware without a '# AEChip:' header line: the sensor "
                      "size is unknown");
    offset_ = pos;
  }

  void check_header_line(std::string line, bool first_line, std::uint64_t end) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (first_line && line.rfind(kAedat2Magic, 0) != 0)
      throw ReadError(file_.path(), 0, -1, "not an AEDAT 2.0 file (first line '" + line + "')");
    constexpr std::string_view kChip = "# AEChip:";
    constexpr std::string_view kHardware = "# HardwareInterface:";
    if (line.rfind(kHardware, 0) == 0 && line.find("DAVIS") != std::string::npos) davis_hardware_ = true;
    if (line.find("created by AEDat2Output in v2e") != std::string::npos) written_by_v2e_ = true;
    if (line.rfind(kChip, 0) != 0) return;
    const std::string name = line.substr(kChip.size());
    const Aedat2Chip* chip = find_aedat2_chip(name);
    if (chip == nullptr)
      throw ReadError(file_.path(), static_cast<std::int64_t>(end), -1,
                      "AEDAT 2.0 from chip '" + name + "': unknown address layout (known chips: " +
                          known_aedat2_chips() + ")");
    chip_ = chip;
    chip_line_ = true;
  }

  // v2e's sensor: a DAVIS240 where no DVS event's raw x reaches 240 nor its
  // raw y 180, else a DAVIS346 (a pass over the records' addresses).
  const Aedat2Chip& v2e_chip() {
    std::uint32_t max_x = 0, max_y = 0;
    for (std::uint64_t at = offset_;;) {
      const std::size_t got = file_.read_at(at, buffer_);
      const auto* bytes = reinterpret_cast<const unsigned char*>(buffer_.data());
      for (std::size_t r = 0; r + kRecordBytes <= got; r += kRecordBytes) {
        const std::uint32_t address = load_be32(bytes + r);
        if ((address & kDavisNotDvs) != 0 || (address & kDavisTypeMask) == kDavisExternal) continue;
        max_x = std::max(max_x, davis_raw_x(address));
        max_y = std::max(max_y, davis_raw_y(address));
      }
      if (got < buffer_.size()) break;
      at += got;
    }
    const Aedat2Chip* smaller = find_aedat2_chip(kV2eChips[0]);
    const bool fits_smaller =
        max_x < static_cast<std::uint32_t>(smaller->width) && max_y < static_cast<std::uint32_t>(smaller->height);
    return fits_smaller ? *smaller : *find_aedat2_chip(kV2eChips[1]);
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
  const Aedat2Chip* chip_;
  bool chip_line_ = false;
  bool davis_hardware_ = false;
  bool written_by_v2e_ = false;  // v2e's AEDAT 2.0 writer: DAVIS layout, no AEChip line
  bool sensor_from_user_ = false;  // v2e's: ReaderOptions::sensor chose the chip
  std::vector<std::byte> buffer_;
  std::size_t buffer_pos_ = 0;
  std::size_t buffer_end_ = 0;
  std::uint64_t offset_ = 0;      // file offset of buffer_[buffer_pos_]
  std::uint64_t next_index_ = 0;  // index of the next event delivered
  SkippedKinds<kSkippedKinds> skipped_{kAedat2SkippedNames};
  WrappingCounter<32> clock_;
  std::uint64_t batch_first_index_ = 0;
  std::uint64_t batch_first_offset_ = 0;
  // (event index, records skipped in this batch before it), one entry per index.
  std::vector<std::pair<std::uint64_t, std::uint64_t>> skips_in_batch_;
  std::uint64_t skipped_in_batch_ = 0;
  std::optional<ReadError> pending_;
};

SniffResult sniff_aedat2(std::span<const std::byte> head, std::string_view path) {
  if (head.size() >= kAedat2Magic.size() &&
      std::memcmp(head.data(), kAedat2Magic.data(), kAedat2Magic.size()) == 0)
    return SniffResult::by_content;
  (void)path;  // .aedat is shared by AEDAT 2/3/4: never sniff by extension alone
  return SniffResult::no;
}

std::unique_ptr<EventReader> open_aedat2(const std::string& path, const ReaderOptions& options) {
  return std::make_unique<Aedat2Reader>(path, options.sensor);
}

}  // namespace

const ReaderFormat aedat2_format{"aedat2",
                                 "jAER AEDAT 2.0 from a DVS128 or a DAVIS, or v2e's ('#!AER-DAT2.0' header, "
                                 "big-endian u32 address + u32 timestamp in us; APS, IMU and "
                                 "external events skipped and counted)",
                                 &sniff_aedat2, nullptr, &open_aedat2};

}  // namespace evlife::io::detail
