// Binary augmented events: see augmented_bin_format.h / README.
#include "augmented_bin_format.h"
#include "augmented_formats.h"
#include "output_file.h"

namespace evlife::io::detail {
namespace {

class AugmentedBinWriter final : public AugmentedEventWriter {
 public:
  AugmentedBinWriter(const std::string& path, SensorSize sensor) : file_(path, {augmented_bin::kHeaderBytes, augmented_bin::kRecordBytes}) {
    using namespace augmented_bin;
    unsigned char header[kHeaderBytes] = {};
    std::memcpy(header, kMagic.data(), kMagic.size());
    put<std::uint16_t>(header, 8, kVersion);
    put<std::uint16_t>(header, 10, static_cast<std::uint16_t>(kHeaderBytes));
    put<std::uint16_t>(header, 12, static_cast<std::uint16_t>(kRecordBytes));
    put<std::uint16_t>(header, 14, 0);
    put<std::uint32_t>(header, 16, static_cast<std::uint32_t>(sensor.width));
    put<std::uint32_t>(header, 20, static_cast<std::uint32_t>(sensor.height));
    file_.append(header, sizeof header);
  }

  void write(std::span<const AugmentedEvent> events) override {
    using namespace augmented_bin;
    for (const AugmentedEvent& a : events) {
      auto* r = reinterpret_cast<unsigned char*>(file_.reserve(kRecordBytes));
      encode(a, r);
      file_.commit(kRecordBytes);
    }
  }

  void close() override { file_.close(); }
  const std::string& path() const override { return file_.path(); }

 private:
  OutputFile file_;
};

}  // namespace

std::unique_ptr<AugmentedEventWriter> open_augmented_bin_writer(const std::string& path,
                                                                SensorSize sensor) {
  return std::make_unique<AugmentedBinWriter>(path, sensor);
}

}  // namespace evlife::io::detail
