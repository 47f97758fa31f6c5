// Private: constructors of the augmented writers/readers, chosen by
// open_augmented_writer / open_augmented_reader.
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include "evlife/io/augmented_event_reader.h"
#include "evlife/io/augmented_event_writer.h"

namespace evlife::io::detail {

inline constexpr std::string_view kAugmentedCsvHeader = "x,y,t,p,lifetime,vx,vy,prediction_error";

std::unique_ptr<AugmentedEventWriter> open_augmented_csv_writer(const std::string& path);
std::unique_ptr<AugmentedEventWriter> open_augmented_bin_writer(const std::string& path,
                                                                SensorSize sensor);
std::unique_ptr<AugmentedEventReader> open_augmented_csv_reader(const std::string& path);
std::unique_ptr<AugmentedEventReader> open_augmented_bin_reader(const std::string& path);

/// True when `head` (a file's first bytes) is HDF5's signature.
bool starts_like_hdf5(std::string_view head);
/// evlife's augmented HDF5 output (x, y, t, p with lifetime, vx, vy,
/// prediction_error), else nullptr (plain events, another tool's layout, or a
/// build without HDF5). Throws ReadError for a file that does not open as
/// HDF5 events or whose augmented columns do not read.
std::unique_ptr<AugmentedEventReader> open_augmented_hdf5_reader(const std::string& path);

}  // namespace evlife::io::detail
