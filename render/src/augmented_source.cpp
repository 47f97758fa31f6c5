#include "evlife/render/augmented_source.h"

#include <algorithm>
#include <array>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <vector>

#include "evlife/io/augmented_event_reader.h"
#include "evlife/io/estimating_reader.h"
#include "evlife/io/event_reader.h"
#include "evlife/io/sensor_size_from_data.h"

namespace evlife::render {

namespace {

std::string file_name(const std::string& path) {
  return std::filesystem::path(path).filename().string();
}

class AugmentedFileSource final : public AugmentedSource {
 public:
  AugmentedFileSource(std::unique_ptr<io::AugmentedEventReader> reader, SensorSize sensor)
      : reader_(std::move(reader)), sensor_(sensor) {}
  std::size_t read(std::span<AugmentedEvent> out) override { return reader_->read(out); }
  SensorSize sensor() const override { return sensor_; }
  std::string description() const override {
    return file_name(reader_->path()) + " (" + std::string(reader_->format_name()) +
           ", lifetimes from the file)";
  }
  const LifetimeStats* estimator_stats() const override { return nullptr; }

 private:
  std::unique_ptr<io::AugmentedEventReader> reader_;
  SensorSize sensor_;
};

// The estimator's planes (40 B a pixel: 1.3 GB on a 4096x4096 sensor) are
// allocated and written at the first read, not when the source is opened: a
// command that refuses its job once the sensor is known (a frame too large for
// the memory) says so at once, without first touching them.
class EstimatingSource final : public AugmentedSource {
 public:
  EstimatingSource(std::unique_ptr<io::EventReader> reader, const LifetimeOptions& options)
      : reader_(std::move(reader)), options_(options) {
    // Bad options are refused here, as the estimator's constructor would.
    if (const std::string err = validate_lifetime_options(options); !err.empty()) {
      throw std::invalid_argument("LifetimeOptions." + err);
    }
  }
  std::size_t read(std::span<AugmentedEvent> out) override {
    if (!estimating_) {
      estimator_.emplace(options_);
      estimating_.emplace(*reader_, *estimator_, 4096);
    }
    return estimating_->read(out);
  }
  SensorSize sensor() const override { return options_.sensor; }
  std::string description() const override {
    return file_name(reader_->path()) + " (" + std::string(reader_->format_name()) +
           ", estimated on the fly, N=" + std::to_string(options_.window_size) +
           (options_.regularization ? ", regularized" : ", not regularized") + ")";
  }
  const LifetimeStats* estimator_stats() const override { return estimator_ ? &estimator_->stats() : &no_events_; }
  std::uint64_t bytes_consumed() const override { return reader_->bytes_consumed(); }
  const io::EventReader* event_reader() const override { return reader_.get(); }

 private:
  std::unique_ptr<io::EventReader> reader_;
  LifetimeOptions options_;
  LifetimeStats no_events_{};  // the counters before the first read
  std::optional<LifetimeEstimator> estimator_;
  std::optional<io::EstimatingReader> estimating_;  // after the two it refers to
};

}  // namespace

std::unique_ptr<AugmentedSource> open_augmented_source(const std::string& path,
                                                       const LifetimeOptions& estimator,
                                                       std::optional<SensorSize> sensor,
                                                       const io::ReaderOptions& input,
                                                       const std::atomic<bool>* stop) {
  std::unique_ptr<io::AugmentedEventReader> augmented;
  io::ReadError augmented_error(path, -1, -1, "");
  try {
    augmented = io::open_augmented_reader(path);
  } catch (const io::AugmentedColumnsError&) {  // evlife's .h5, damaged: said so, not estimated again
    throw;
  } catch (const io::ReadError& e) {
    if (io::names_augmented_bin(path)) throw;  // named as evlife's output: read as one, or say why not
    augmented_error = e;
  }
  if (augmented) {
    const SensorSize s = io::sensor_size_of_augmented(path, sensor);
    return std::make_unique<AugmentedFileSource>(std::move(augmented), s);
  }
  std::unique_ptr<io::EventReader> raw;
  try {
    raw = io::open_event_reader(path, input);
  } catch (const io::OptionNotTaken&) {  // the format is known: the option is at fault, not the file
    throw;
  } catch (const io::ReadError& e) {
    throw io::ReadError(path, e.byte_offset(), e.event_index(),
                        e.reason() + " (and not an augmented file: " + augmented_error.reason() + ")");
  }
  LifetimeOptions options = estimator;
  options.sensor = io::resolve_sensor_size(path, sensor, input, stop).size;
  // The checked reader: coordinates outside the sensor and time going
  // backwards are reported (file, event index, offset), never silently used.
  io::ReaderOptions checked = input;
  checked.sensor = options.sensor;
  checked.require_time_order = true;
  raw = io::open_event_reader(path, checked);
  return std::make_unique<EstimatingSource>(std::move(raw), options);
}

std::unique_ptr<AugmentedSource> make_estimating_source(std::unique_ptr<io::EventReader> reader,
                                                        const LifetimeOptions& options) {
  return std::make_unique<EstimatingSource>(std::move(reader), options);
}

}  // namespace evlife::render
