// Reads the binary augmented format back (see augmented_bin_format.h).
#include <cmath>
#include <vector>

#include "augmented_bin_format.h"
#include "augmented_formats.h"
#include "input_file.h"

namespace evlife::io::detail {
namespace {

class AugmentedBinReader final : public AugmentedEventReader {
 public:
  explicit AugmentedBinReader(const std::string& path) : file_(path) {
    using namespace augmented_bin;
    unsigned char header[kHeaderBytes];
    const std::size_t got = file_.read_at(0, std::as_writable_bytes(std::span(header)));
    if (got < kMagic.size() || std::memcmp(header, kMagic.data(), kMagic.size()) != 0)
      throw ReadError(path, 0, -1, "not an evlife augmented .bin file (bad magic)");
    if (got != kHeaderBytes)
      throw ReadError(path, static_cast<std::int64_t>(got), -1,
                      "truncated: the header needs " + std::to_string(kHeaderBytes) + " bytes, the file has " +
                          std::to_string(got));
    const auto version = get<std::uint16_t>(header, 8);
    header_bytes_ = get<std::uint16_t>(header, 10);
    record_bytes_ = get<std::uint16_t>(header, 12);
    // Version 1's sizes are its own: other sizes in a version-1 header are
    // corruption (a record of 4896 B read every 153rd event), not a later
    // version's appended fields.
    const bool sizes_fit_version = version == 1 ? header_bytes_ == kHeaderBytes && record_bytes_ == kRecordBytes
                                                : header_bytes_ >= kHeaderBytes && record_bytes_ >= kRecordBytes;
    if (version < 1 || !sizes_fit_version)
      throw ReadError(path, 8, -1,
                      "unsupported augmented .bin header (version " + std::to_string(version) +
                          ", header " + std::to_string(header_bytes_) + " B, record " +
                          std::to_string(record_bytes_) + " B)");
    // A later version's longer header, cut or corrupt: no record to read was 0 events and exit 0.
    if (file_.size_bytes() < header_bytes_)
      throw ReadError(path, static_cast<std::int64_t>(file_.size_bytes()), -1,
                      "truncated: the header needs " + std::to_string(header_bytes_) + " bytes, the file has " +
                          std::to_string(file_.size_bytes()));
    const auto width = get<std::uint32_t>(header, 16);
    const auto height = get<std::uint32_t>(header, 20);
    // 0x0: no size stated (convert of a CSV without --sensor). One side of
    // 0 px blamed every event for lying outside the sensor.
    if ((width == 0) != (height == 0) || width > 65536 || height > 65536)
      throw ReadError(path, 16, -1,
                      "implausible sensor size in the header: " + std::to_string(width) + "x" + std::to_string(height) +
                          " (corrupt header?)");
    sensor_ = SensorSize{static_cast<int>(width), static_cast<int>(height)};
    offset_ = header_bytes_;
    buffer_.resize(record_bytes_ * 8192);
  }

  std::size_t read(std::span<AugmentedEvent> out) override {
    if (pending_) throw *pending_;
    std::size_t n = 0;
    while (n < out.size()) {
      const std::size_t want = std::min(out.size() - n, buffer_.size() / record_bytes_);
      const std::size_t got = file_.read_at(offset_, std::span(buffer_).first(want * record_bytes_));
      const std::size_t records = got / record_bytes_;
      const auto* bytes = reinterpret_cast<const unsigned char*>(buffer_.data());
      for (std::size_t i = 0; i < records; ++i) out[n + i] = augmented_bin::decode(bytes + i * record_bytes_);
      const RecordFault bad = first_unreadable_record(out.subspan(n, records), sensor_, last_t_us_);
      if (bad.index > 0) last_t_us_ = out[n + bad.index - 1].event.t_us;
      n += bad.index;
      offset_ += bad.index * record_bytes_;
      index_ += bad.index;
      if (bad.index < records) {
        fault(bad.what);
        break;
      }
      if (records < want) {
        if (got % record_bytes_ != 0)
          fault("truncated: " + std::to_string(got % record_bytes_) + " trailing bytes, a record is " +
                std::to_string(record_bytes_));
        break;
      }
    }
    if (n == 0 && pending_) throw *pending_;
    return n;
  }

  // A header of 0 x 0 states none (convert of events of no known sensor).
  std::optional<SensorSize> sensor_size() const override {
    return sensor_.pixel_count() > 0 ? std::optional(sensor_) : std::nullopt;
  }
  std::string_view format_name() const override { return "augmented-bin"; }
  const std::string& path() const override { return file_.path(); }

 private:
  void fault(const std::string& what) {
    pending_.emplace(file_.path(), static_cast<std::int64_t>(offset_),
                     static_cast<std::int64_t>(index_), what);
  }

  InputFile file_;
  std::size_t header_bytes_ = 0, record_bytes_ = 0;
  SensorSize sensor_;
  std::uint64_t offset_ = 0, index_ = 0;
  std::int64_t last_t_us_ = INT64_MIN;
  std::vector<std::byte> buffer_;
  std::optional<ReadError> pending_;
};

}  // namespace

std::unique_ptr<AugmentedEventReader> open_augmented_bin_reader(const std::string& path) {
  return std::make_unique<AugmentedBinReader>(path);
}

}  // namespace evlife::io::detail
