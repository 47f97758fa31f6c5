#include "evlife/io/augmented_event_writer.h"

#include "augmented_formats.h"
#include "evlife/io/hdf5_writer.h"
#include "evlife_bin_magic.h"
#include "reader_registry.h"  // has_extension

namespace evlife::io {

namespace {
bool names_hdf5(const std::string& path) {
  return detail::has_extension(path, ".h5") || detail::has_extension(path, ".hdf5");
}
}  // namespace

bool names_an_augmented_output(const std::string& path) {
  return detail::has_extension(path, ".csv") || detail::named_like_augmented_bin(path) || names_hdf5(path);
}

std::unique_ptr<AugmentedEventWriter> open_augmented_writer(const std::string& path,
                                                            SensorSize sensor) {
  if (detail::has_extension(path, ".csv")) return detail::open_augmented_csv_writer(path);
  if (detail::named_like_augmented_bin(path)) return detail::open_augmented_bin_writer(path, sensor);
  // HDF5 (h5py-readable columns).
  if (names_hdf5(path)) {
    return open_hdf5_augmented_writer(
        path, sensor.width > 0 ? std::optional<SensorSize>(sensor) : std::nullopt);
  }
  throw WriteError(path, "unknown output format: use a .csv, .bin or .h5 file name");
}

}  // namespace evlife::io
