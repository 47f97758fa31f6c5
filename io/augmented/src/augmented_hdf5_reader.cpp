// Reads evlife's augmented HDF5 output back (what Hdf5Writer writes for
// augmented events): the events through the HDF5 reader (its checks, its
// units), the lifetime, velocity and prediction-error columns row for row
// beside them.
#include <algorithm>
#include <array>
#include <vector>

#include "augmented_formats.h"
#include "hdf5_reader.h"
#include "hdf5_signature.h"

namespace evlife::io::detail {
namespace {

// In the order of AugmentedEvent's fields after the event.
constexpr std::array<const char*, 4> kFloatColumns{"lifetime", "vx", "vy", "prediction_error"};

class AugmentedHdf5Reader final : public AugmentedEventReader {
 public:
  explicit AugmentedHdf5Reader(std::unique_ptr<Hdf5Reader> events) : events_(std::move(events)) {
    sensor_ = events_->sensor_size().value_or(SensorSize{0, 0});
    events_buffer_.resize(kBlock);
    for (auto& column : columns_) column.resize(kColumnRows);
  }

  std::size_t read(std::span<AugmentedEvent> out) override {
    if (pending_) throw *pending_;
    const std::size_t want = std::min(out.size(), kBlock);
    // The events' own faults (a row that is no event) come after the rows
    // before them, as from every reader.
    const std::size_t n = events_->read(std::span(events_buffer_).first(want));
    if (n == 0) return 0;
    if (index_ < columns_first_ || index_ + n > columns_first_ + columns_rows_) {
      // The next kColumnRows rows of the four columns at once: each read is
      // a round trip to the reader's child (hdf5_read_child.h).
      const auto rows = static_cast<std::size_t>(
          std::min<std::int64_t>(events_->event_count() - static_cast<std::int64_t>(index_), kColumnRows));
      const std::array<float*, 4> columns{columns_[0].data(), columns_[1].data(), columns_[2].data(),
                                          columns_[3].data()};
      try {
        events_->read_float_rows(static_cast<std::int64_t>(index_), rows, columns);  // (n <= rows: read as events)
        columns_rows_ = rows;
      } catch (const ReadError&) {
        // A value no float holds further on: this block's rows alone, so that
        // the blocks before it are delivered and the error names its own.
        events_->read_float_rows(static_cast<std::int64_t>(index_), n, columns);
        columns_rows_ = n;
      }
      columns_first_ = index_;
    }
    const std::size_t at = index_ - columns_first_;
    for (std::size_t i = 0; i < n; ++i) {
      out[i] = AugmentedEvent{events_buffer_[i], columns_[0][at + i], columns_[1][at + i], columns_[2][at + i],
                              columns_[3][at + i]};
    }
    const RecordFault bad = first_unreadable_record(out.first(n), sensor_, last_t_us_);
    if (bad.index > 0) last_t_us_ = out[bad.index - 1].event.t_us;
    index_ += bad.index;
    if (bad.index < n) {
      pending_.emplace(events_->path(), -1, static_cast<std::int64_t>(index_), bad.what);
      if (bad.index == 0) throw *pending_;
    }
    return bad.index;
  }

  std::optional<SensorSize> sensor_size() const override {
    return sensor_.pixel_count() > 0 ? std::optional(sensor_) : std::nullopt;
  }
  std::string_view format_name() const override { return "augmented-hdf5"; }
  const std::string& path() const override { return events_->path(); }

 private:
  static constexpr std::size_t kBlock = 8192;
  static constexpr std::size_t kColumnRows = Hdf5Reader::kChunkEvents;
  static_assert(kColumnRows >= kBlock);

  std::unique_ptr<Hdf5Reader> events_;
  SensorSize sensor_;
  std::vector<Event> events_buffer_;
  std::array<std::vector<float>, 4> columns_;
  std::uint64_t index_ = 0;  // rows delivered
  std::uint64_t columns_first_ = 0, columns_rows_ = 0;  // the rows columns_ hold
  std::int64_t last_t_us_ = INT64_MIN;
  std::optional<ReadError> pending_;
};

}  // namespace

bool starts_like_hdf5(std::string_view head) { return starts_with_hdf5_signature(head.data(), head.size()); }

std::unique_ptr<AugmentedEventReader> open_augmented_hdf5_reader(const std::string& path) {
  auto events = std::make_unique<Hdf5Reader>(path);
  try {
    if (!events->open_float_columns(kFloatColumns)) return nullptr;
  } catch (const ReadError& e) {
    throw AugmentedColumnsError(e.path(), e.byte_offset(), e.event_index(), e.reason());
  }
  return std::make_unique<AugmentedHdf5Reader>(std::move(events));
}

}  // namespace evlife::io::detail
