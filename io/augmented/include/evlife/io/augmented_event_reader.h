// Readers of the files written by open_augmented_writer (.csv, .bin, .h5),
// streaming, with the same error rules as EventReader: the good records come
// first, then the next read() throws ReadError naming the file and the
// record index / byte offset.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "evlife/algo/event.h"
#include "evlife/io/event_reader.h"  // ReadError

namespace evlife::io {

class AugmentedEventReader {
 public:
  virtual ~AugmentedEventReader() = default;
  /// Up to out.size() records in file order; 0 = end.
  virtual std::size_t read(std::span<AugmentedEvent> out) = 0;
  /// From the .bin header or the .h5 attributes (nullopt where they state
  /// none or 0 x 0); nullopt for CSV.
  virtual std::optional<SensorSize> sensor_size() const = 0;
  virtual std::string_view format_name() const = 0;  ///< "augmented-csv" / "-bin" / "-hdf5"
  virtual const std::string& path() const = 0;
};

/// Why an augmented record's values are none the estimator writes (a
/// lifetime that is negative, NaN or infinite; a velocity that is not
/// finite; an infinite prediction error: NaN is "none"), or nullopt.
std::optional<std::string> augmented_values_fault(const AugmentedEvent& a);

/// The first of `records` an augmented file may not hold after a record at
/// `last_t_us`: polarity not +1/-1, outside `sensor` (width 0: any size),
/// time going backwards, values augmented_values_fault() refuses. `index` ==
/// records.size() when there is none. The rule of every augmented reader and
/// writer, and of what evlife.write and evlife.frame accept.
struct RecordFault {
  std::size_t index = 0;
  std::string what;  ///< empty when none
};
RecordFault first_unreadable_record(std::span<const AugmentedEvent> records, SensorSize sensor,
                                    std::int64_t last_t_us);

/// HDF5 events holding some of evlife's augmented columns but not all, or one
/// that is no float column of the events' length: evlife's output, damaged.
/// The callers that fall back to reading a file as plain events do not for it.
struct AugmentedColumnsError : ReadError {
  using ReadError::ReadError;
};

/// Sniffs the .bin magic, else HDF5's signature (then the augmented columns
/// beside x, y, t, p), else expects the CSV header (a file named .bin: the
/// magic). Throws ReadError for a missing file or unknown content.
std::unique_ptr<AugmentedEventReader> open_augmented_reader(const std::string& path);

/// True for a path named like evlife's binary output (.bin, which no other
/// format evlife reads uses): a file so named that no reader takes is
/// reported as a bad .bin, not with the list of every format.
bool names_augmented_bin(const std::string& path);

/// evlife's own output when the content says so (the .bin magic, HDF5 with
/// the augmented columns, the augmented CSV header), else nullptr: for callers that take any recording
/// (a stream's copy has no extension), also for a path that cannot be opened
/// (the caller's other readers name the reason). Throws ReadError for a file
/// with the .bin magic or name that does not read.
std::unique_ptr<AugmentedEventReader> open_if_augmented(const std::string& path);

/// The sensor of an augmented file: the one the file states (.bin) when it
/// is a camera's, else `user` when given, else {max x + 1, max y + 1} of its
/// events (one pass; the rule of sensor_size_from_data for raw files). Throws
/// ReadError for an unreadable or corrupt file, one holding no event, or a
/// stated or spanned side beyond kMaxSensorSide without `user`.
SensorSize sensor_size_of_augmented(const std::string& path, std::optional<SensorSize> user = {});

}  // namespace evlife::io
