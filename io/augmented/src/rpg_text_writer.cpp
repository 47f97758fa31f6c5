// RPG text writer: `t x y p` with t in seconds and exactly 6 decimals,
// formatted from integer µs (no floating point, so it reads back exactly).
#include <charconv>

#include "evlife/io/event_writer.h"
#include "evlife/io/hdf5_writer.h"
#include "output_file.h"
#include "reader_registry.h"  // has_extension

namespace evlife::io {
namespace {

class RpgTextWriter final : public EventWriter {
 public:
  explicit RpgTextWriter(const std::string& path) : file_(path) {}

  void write(std::span<const Event> events) override {
    for (const Event& e : events) {
      char* const start = file_.reserve(64);
      char* p = start;
      char* const end = start + 64;
      std::int64_t t = e.t_us;
      // |t| without overflow for INT64_MIN, split into seconds and µs.
      std::uint64_t magnitude = t < 0 ? 0 - static_cast<std::uint64_t>(t) : static_cast<std::uint64_t>(t);
      if (t < 0) *p++ = '-';
      p = std::to_chars(p, end, magnitude / 1'000'000).ptr;
      *p++ = '.';
      std::uint64_t micro = magnitude % 1'000'000;
      for (int d = 5; d >= 0; --d, micro /= 10) p[d] = static_cast<char>('0' + micro % 10);
      p += 6;
      *p++ = ' ';
      p = std::to_chars(p, end, e.x).ptr;
      *p++ = ' ';
      p = std::to_chars(p, end, e.y).ptr;
      *p++ = ' ';
      *p++ = e.p > 0 ? '1' : '0';
      *p++ = '\n';
      file_.commit(static_cast<std::size_t>(p - start));
    }
  }

  void close() override { file_.close(); }
  const std::string& path() const override { return file_.path(); }

 private:
  detail::OutputFile file_;
};

}  // namespace

std::unique_ptr<EventWriter> open_rpg_text_writer(const std::string& path) {
  return std::make_unique<RpgTextWriter>(path);
}

std::unique_ptr<EventWriter> open_event_writer(const std::string& path, std::optional<SensorSize> sensor) {
  if (detail::has_extension(path, ".txt")) return open_rpg_text_writer(path);  // no place for a sensor
  if (detail::has_extension(path, ".h5") || detail::has_extension(path, ".hdf5")) {
    return open_hdf5_event_writer(path, sensor);
  }
  throw WriteError(path, "unknown event output format: use a .txt (RPG text) or .h5 (HDF5) file name");
}

}  // namespace evlife::io
