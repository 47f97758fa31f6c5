// CSV of augmented events. Floats are written in the shortest form that
// reads back to the same float (std::to_chars), so the CSV loses nothing and
// is fast to produce.
#include <charconv>
#include <cmath>

#include "augmented_formats.h"
#include "output_file.h"

namespace evlife::io::detail {
namespace {

constexpr std::size_t kMaxRowBytes = 160;  // 2×5 + 20 + 2 + 4×15 + 8 separators, rounded up

class AugmentedCsvWriter final : public AugmentedEventWriter {
 public:
  explicit AugmentedCsvWriter(const std::string& path) : file_(path, {.header_lines = 1}) {
    file_.append(kAugmentedCsvHeader.data(), kAugmentedCsvHeader.size());
    file_.append("\n", 1);
  }

  void write(std::span<const AugmentedEvent> events) override {
    for (const AugmentedEvent& a : events) {
      char* const start = file_.reserve(kMaxRowBytes);
      char* p = start;
      char* const end = start + kMaxRowBytes;
      p = std::to_chars(p, end, a.event.x).ptr;
      *p++ = ',';
      p = std::to_chars(p, end, a.event.y).ptr;
      *p++ = ',';
      p = std::to_chars(p, end, a.event.t_us).ptr;
      *p++ = ',';
      p = std::to_chars(p, end, static_cast<int>(a.event.p)).ptr;
      *p++ = ',';
      p = std::to_chars(p, end, a.lifetime_us).ptr;
      *p++ = ',';
      p = std::to_chars(p, end, a.vx_px_s).ptr;
      *p++ = ',';
      p = std::to_chars(p, end, a.vy_px_s).ptr;
      *p++ = ',';
      if (!std::isnan(a.prediction_error_us)) p = std::to_chars(p, end, a.prediction_error_us).ptr;
      *p++ = '\n';
      file_.commit(static_cast<std::size_t>(p - start));
    }
  }

  void close() override { file_.close(); }
  const std::string& path() const override { return file_.path(); }

 private:
  OutputFile file_;
};

}  // namespace

std::unique_ptr<AugmentedEventWriter> open_augmented_csv_writer(const std::string& path) {
  return std::make_unique<AugmentedCsvWriter>(path);
}

}  // namespace evlife::io::detail
