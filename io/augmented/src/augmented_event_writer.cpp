#include "evlife/io/augmented_event_writer.h"

#include <cstdint>
#include <memory>
#include <string>
#include <utility>

#include "augmented_formats.h"
#include "evlife/io/augmented_event_reader.h"
#include "evlife/io/hdf5_writer.h"
#include "evlife_bin_magic.h"
#include "reader_registry.h"  // has_extension

namespace evlife::io {

namespace {
bool names_hdf5(const std::string& path) {
  return detail::has_extension(path, ".h5") || detail::has_extension(path, ".hdf5");
}

// Writes only what the readers take back (first_unreadable_record()): a
// record they refuse (a time going back after a camera's clock restarted, a
// polarity or a lifetime no estimator writes) ends the writing there, named,
// instead of a file every reader stops at.
class CheckedAugmentedWriter final : public AugmentedEventWriter {
 public:
  CheckedAugmentedWriter(std::unique_ptr<AugmentedEventWriter> inner, SensorSize sensor)
      : inner_(std::move(inner)), sensor_(sensor) {}
  void write(std::span<const AugmentedEvent> events) override {
    const RecordFault bad = first_unreadable_record(events, sensor_, last_t_us_);
    inner_->write(events.first(bad.index));
    if (bad.index > 0) last_t_us_ = events[bad.index - 1].event.t_us;
    written_ += bad.index;
    if (bad.index < events.size()) {
      throw WriteError(inner_->path(), "record " + std::to_string(written_) + " (counting from 0): " + bad.what +
                                           ": no reader would take it back, so it is not written (after a camera's "
                                           "clock restarts, write to a new file)");
    }
  }
  void close() override { inner_->close(); }
  const std::string& path() const override { return inner_->path(); }

 private:
  std::unique_ptr<AugmentedEventWriter> inner_;
  SensorSize sensor_;
  std::int64_t last_t_us_ = INT64_MIN;
  std::uint64_t written_ = 0;
};

std::unique_ptr<AugmentedEventWriter> open_unchecked_writer(const std::string& path, SensorSize sensor) {
  if (detail::has_extension(path, ".csv")) return detail::open_augmented_csv_writer(path);
  if (detail::named_like_augmented_bin(path)) return detail::open_augmented_bin_writer(path, sensor);
  // HDF5 (h5py-readable columns).
  if (names_hdf5(path)) {
    return open_hdf5_augmented_writer(
        path, sensor.width > 0 ? std::optional<SensorSize>(sensor) : std::nullopt);
  }
  throw WriteError(path, "unknown output format: use a .csv, .bin or .h5 file name");
}
}  // namespace

bool names_an_augmented_output(const std::string& path) {
  return detail::has_extension(path, ".csv") || detail::named_like_augmented_bin(path) || names_hdf5(path);
}

std::unique_ptr<AugmentedEventWriter> open_augmented_writer(const std::string& path,
                                                            SensorSize sensor) {
  // A CSV states no sensor: its reader takes any coordinates.
  const SensorSize stated = detail::has_extension(path, ".csv") ? SensorSize{0, 0} : sensor;
  return std::make_unique<CheckedAugmentedWriter>(open_unchecked_writer(path, sensor), stated);
}

}  // namespace evlife::io
