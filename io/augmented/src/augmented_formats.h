// Private: constructors of the augmented writers/readers, chosen by
// open_augmented_writer / open_augmented_reader.
#pragma once

#include <memory>
#include <string>

#include "evlife/io/augmented_event_reader.h"
#include "evlife/io/augmented_event_writer.h"

namespace evlife::io::detail {

inline constexpr std::string_view kAugmentedCsvHeader = "x,y,t,p,lifetime,vx,vy,prediction_error";

std::unique_ptr<AugmentedEventWriter> open_augmented_csv_writer(const std::string& path);
std::unique_ptr<AugmentedEventWriter> open_augmented_bin_writer(const std::string& path,
                                                                SensorSize sensor);
std::unique_ptr<AugmentedEventReader> open_augmented_csv_reader(const std::string& path);
std::unique_ptr<AugmentedEventReader> open_augmented_bin_reader(const std::string& path);

}  // namespace evlife::io::detail
