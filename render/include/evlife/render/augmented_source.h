// Where rendered events come from: an augmented recording written by
// `evlife process` (.bin/.csv), or a raw recording processed on the fly by the
// lifetime estimator. Streaming, constant memory.
#pragma once

#include <cstddef>
#include <atomic>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "evlife/algo/event.h"
#include "evlife/algo/lifetime_estimator.h"
#include "evlife/algo/lifetime_options.h"
#include "evlife/io/event_reader.h"

namespace evlife::render {

class AugmentedSource {
 public:
  virtual ~AugmentedSource() = default;
  /// Up to out.size() augmented events in file order; 0 = end. Read errors
  /// throw evlife::io::ReadError after the good events were returned.
  virtual std::size_t read(std::span<AugmentedEvent> out) = 0;
  virtual SensorSize sensor() const = 0;
  /// e.g. "stripes.mat (mat, estimated on the fly, N=5, regularized)".
  virtual std::string description() const = 0;
  /// Estimator counters when the events are estimated on the fly, else null.
  virtual const LifetimeStats* estimator_stats() const = 0;
  /// Bytes of the input consumed so far, 0 when unknown (for progress).
  virtual std::uint64_t bytes_consumed() const { return 0; }
  /// The recording's reader when its events are estimated on the fly (its
  /// skipped records, for the summaries), else null.
  virtual const io::EventReader* event_reader() const { return nullptr; }
};

/// Augments the events of `reader` with a LifetimeEstimator(options) as they
/// are read (e.g. a SyntheticSceneReader). Throws std::invalid_argument.
std::unique_ptr<AugmentedSource> make_estimating_source(std::unique_ptr<io::EventReader> reader,
                                                        const LifetimeOptions& options);

/// Opens `path`: an augmented file is read as is; anything else is read by
/// io::open_event_reader and augmented by a LifetimeEstimator with
/// `estimator` (its sensor replaced by the resolved one). `sensor`: the size
/// when the file states none (or one no camera has). Throws io::ReadError (file at fault, both attempts
/// explained) or std::invalid_argument (bad options). `input`: the input
/// selection for event files (topic...; its sensor is replaced). `stop` (a
/// command's stop flag) ends the scan of a file for its sensor size early:
/// check it after the call, the source then holds a partial size.
std::unique_ptr<AugmentedSource> open_augmented_source(const std::string& path,
                                                       const LifetimeOptions& estimator,
                                                       std::optional<SensorSize> sensor = {},
                                                       const io::ReaderOptions& input = {},
                                                       const std::atomic<bool>* stop = nullptr);

}  // namespace evlife::render
