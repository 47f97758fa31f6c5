// Writers of augmented events (event + lifetime + velocity + prediction
// error): CSV for people and spreadsheets, a compact binary format for speed.
// Both keep one record per input event, in input order, input fields as-is.
#pragma once

#include <memory>
#include <span>
#include <string>

#include "evlife/algo/event.h"
#include "evlife/io/write_error.h"

namespace evlife::io {

class AugmentedEventWriter {
 public:
  /// Never throws: closes without reporting errors if close() was not
  /// called (call close() to learn whether everything reached the disk).
  virtual ~AugmentedEventWriter() = default;

  /// Appends the events (buffered). Throws WriteError naming the file.
  virtual void write(std::span<const AugmentedEvent> events) = 0;

  /// Flushes and closes; throws WriteError if anything failed. Idempotent.
  virtual void close() = 0;

  virtual const std::string& path() const = 0;
};

/// Whether open_augmented_writer() takes `path` by its extension (.csv,
/// .bin, .h5, .hdf5; any case): the commands' check of -o.
bool names_an_augmented_output(const std::string& path);

/// By extension of `path`:
///  - `.csv`: header `x,y,t,p,lifetime,vx,vy,prediction_error`; t, lifetime
///    and prediction_error in µs, vx/vy in px/s, p as 1/-1, prediction_error
///    empty when there was none (NaN); floats in shortest round-trip form.
///  - `.bin`: the evlife augmented binary format (see README, "Binary
///    augmented event format"): 32-byte header, then 32-byte little-endian
///    records.
/// `sensor` is stored in the .bin header (CSV has no place for it).
/// Throws WriteError for an unknown extension or a file that cannot be created.
std::unique_ptr<AugmentedEventWriter> open_augmented_writer(const std::string& path,
                                                            SensorSize sensor);

}  // namespace evlife::io
