// Built instead of hdf5_writer.cpp when EVLIFE_IO_HDF5 is OFF (a core-only
// build, e.g. crossed for a drone computer without libhdf5): asking for an
// .h5 output is a clear error naming the file, never a silent fallback.
#include "augmented_formats.h"
#include "evlife/io/hdf5_writer.h"
#include "evlife/io/write_error.h"

namespace evlife::io {
namespace {
constexpr const char* kNoHdf5 =
    "HDF5 output is not in this build (configured with EVLIFE_IO_HDF5=OFF); use .csv or .bin";
}  // namespace

std::unique_ptr<AugmentedEventWriter> open_hdf5_augmented_writer(const std::string& path,
                                                                 std::optional<SensorSize>) {
  throw WriteError(path, kNoHdf5);
}

std::unique_ptr<EventWriter> open_hdf5_event_writer(const std::string& path,
                                                    std::optional<SensorSize>) {
  throw WriteError(path, kNoHdf5);
}

bool hdf5_exit_would_crash() noexcept { return false; }

namespace detail {

bool starts_like_hdf5(std::string_view) { return false; }  // read as nothing augmented: the readers say why

std::unique_ptr<AugmentedEventReader> open_augmented_hdf5_reader(const std::string&) { return nullptr; }

}  // namespace detail

bool hdf5_exit_would_loop() noexcept { return false; }

}  // namespace evlife::io
