// Writers of HDF5 event files that h5py / NumPy users load in one line:
//     import h5py; f = h5py.File("out.h5"); lifetime_us = f["lifetime"][:]
// One 1-D dataset per field, chunked, shuffled and deflate-compressed:
//     x, y (uint16, px; 0 = left / top), t (int64, µs), p (int8, +1 ON / -1 OFF)
// and for augmented events also
//     lifetime (float32, µs; 0 = noise), vx, vy (float32, px/s),
//     prediction_error (float32, µs; NaN = no prediction).
// Each dataset has a "units" attribute; the root has width / height (px) when
// the sensor is known. open_event_reader reads these files back (x, y, t, p).
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "evlife/algo/event.h"
#include "evlife/io/augmented_event_writer.h"
#include "evlife/io/event_writer.h"

namespace evlife::io {

/// Throws WriteError if the file cannot be created.
std::unique_ptr<AugmentedEventWriter> open_hdf5_augmented_writer(const std::string& path,
                                                                 std::optional<SensorSize> sensor);

/// Plain events (x, y, t, p only). Throws WriteError if the file cannot be created.
std::unique_ptr<EventWriter> open_hdf5_event_writer(const std::string& path,
                                                    std::optional<SensorSize> sensor);

/// True once an HDF5 file failed to close (the disk filled up although the
/// writers keep room for closing: another process took it). libhdf5 1.10
/// then crashes in its exit handler (HDF5 issue #2257), so the process must
/// leave with std::_Exit after flushing its own output.
bool hdf5_exit_would_crash() noexcept;

/// True once an HDF5 file could not be created (e.g. on a full disk). libhdf5
/// 1.10's exit handler then cannot close the library and prints "HDF5:
/// infinite loop closing library" and a line of "FL,FL,..." after the
/// command's own error; the command line leaves with std::_Exit (its other
/// files are closed by then). Nothing is lost: no file was made.
bool hdf5_exit_would_loop() noexcept;

}  // namespace evlife::io
