// Events stored in HDF5, in the layouts the public datasets use:
//  - DSEC: datasets events/x, events/y, events/t (µs), events/p (0/1) and an
//    optional scalar t_offset (µs) added to t;
//  - Prophesee: one compound dataset CD/events with fields x, y, p, t (µs);
//  - evlife (what Hdf5Writer writes): root datasets x, y, t, p (+ augmented
//    columns: open_float_columns), sensor size in root attributes width / height;
//  - event_utils (Stoffregen's tools, E2VID-style training data): datasets
//    events/xs, events/ys, events/ts, events/ps;
//  - v2e (the DVS simulator's --dvs_h5): one N×4 dataset events, rows
//    [t, x, y, p] (t µs, p 0/1); the sensor from its frames (N×h×w) if any;
//  - MVSEC: one N×4 dataset davis/left/events, rows [x, y, t, p] (t s, p ±1;
//    davis/right/events with --topic); the sensor from image_raw beside it;
//  - M3ED: prophesee/left/{x,y,t,p} (prophesee/right with --topic), the
//    sensor from calib/resolution beside them;
//  - with --topic, any group of x, y, t, p columns ("columns").
// A time column of floating-point type holds seconds, an integer one µs.
// Read in chunks of kChunkEvents with the HDF5 library (constant memory) by a
// child process: a crash of the library inside a read ends the child, not
// the caller (hdf5_read_child.h).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "evlife/io/event_reader.h"

namespace evlife::io {
namespace detail {
class Hdf5ReadChild;
}

class Hdf5Reader final : public EventReader {
 public:
  static constexpr std::size_t kChunkEvents = 1 << 16;

  /// Throws ReadError if the file is not HDF5 or holds none of the layouts
  /// above (the message names the datasets looked for). `topic` (--topic):
  /// the N×4 table (MVSEC: davis/right/events) or the group of x, y, t, p
  /// columns (M3ED: prophesee/right) to read instead of the layout's default.
  /// `time_unit` (--time-unit: s, ms, us, ns): the t column's unit, else its
  /// `units` attribute's (as evlife writes it), else seconds for a float
  /// column and µs for an integer one. The Prophesee layout's is µs.
  explicit Hdf5Reader(const std::string& path, const std::string& topic = {}, const std::string& time_unit = {});
  ~Hdf5Reader() override;
  Hdf5Reader(const Hdf5Reader&) = delete;
  Hdf5Reader& operator=(const Hdf5Reader&) = delete;

  std::size_t read(std::span<Event> out) override;
  /// A binary search on the t column (about 2·log2(n) values read): the
  /// index of the first event with t >= t_us, if t is in order.
  std::int64_t skip_events_before(std::int64_t t_us) override;
  std::optional<std::int64_t> first_event_time_us() const override;
  std::optional<SensorSize> sensor_size() const override { return sensor_; }
  std::string_view format_name() const override { return "hdf5"; }
  const std::string& path() const override { return path_; }
  /// Approximate: the share of events loaded, times the file size.
  std::uint64_t bytes_consumed() const override {
    return total_ > 0 ? static_cast<std::uint64_t>(static_cast<double>(file_bytes_) *
                                                   static_cast<double>(next_) /
                                                   static_cast<double>(total_))
                      : 0;
  }

  /// "dsec", "event_utils", "prophesee", "mvsec", "m3ed", "v2e", "evlife" or
  /// "columns" (a group named by --topic).
  std::string_view layout_name() const override { return layout_; }
  /// MVSEC, M3ED: each camera (its table or group, its rows), the one read
  /// marked; none for the other layouts.
  std::vector<ContainerStream> streams() const override;
  std::int64_t event_count() const noexcept { return total_; }

  /// The evlife layout's further columns of rows in step with x, y, t, p
  /// (evlife's augmented output: lifetime, vx, vy, prediction_error), opened
  /// with the checks of the event columns. False when the file holds none of
  /// them (plain events) or is of another layout. Throws ReadError naming a
  /// column that is missing while others are there, is not 1-D floating
  /// point, or has another length than the events.
  bool open_float_columns(std::span<const char* const> names);
  /// Rows [first, first + count) of each column open_float_columns opened,
  /// in its order, as float. Throws ReadError naming the column and the row.
  void read_float_rows(std::int64_t first, std::size_t count, std::span<float* const> out) const;

  // Columns of an N×4 table (v2e, MVSEC): which of the four holds what.
  struct TableColumns {
    int t, x, y, p;
  };

 private:
  using Hid = std::int64_t;  // = hid_t (checked in the .cpp)

  // Layout of one record of the Prophesee compound, as read into memory.
  struct CdRecord {
    std::uint16_t x;
    std::uint16_t y;
    std::int16_t p;
    std::int64_t t;
  };

  void load_chunk();  // next chunk into the column buffers; sets error_ on failure
  bool read_columns(std::size_t count, const char*& what);  // the column datasets' chunk
  bool load_table_chunk(std::size_t count);  // an N×4 table's chunk, converted to the columns
  bool convert_float_times(std::size_t count);    // the chunk's float times in doubles_ into ts_ (µs)
  bool convert_integer_times(std::size_t count);  // the chunk's integer times in ts_ from t_unit_ns_ to µs
  void choose_time_unit(const std::string& time_unit);
  bool stop_at(std::size_t i, const char* column, double value, const char* why);  // a bad row ends the chunk
  void stop_outside_sensor();  // the chunk ends before its first event outside the sensor the file states
  bool is_table() const noexcept { return table_.t >= 0; }
  bool read_time(std::int64_t index, std::int64_t& t_us) const;  // one event's t (+ t_offset)
  // Before the first read (and no error yet): a search may still move the start.
  bool unread() const noexcept { return next_ == 0 && chunk_size_ == 0 && !error_; }
  void close_handles() noexcept;
  std::string why_unread(const char* otherwise) const;  // a failed read's cause, in parentheses
  Hid open_column(const std::string& name);  // with the checks of every column; throws ReadError

  std::string path_;
  // Does the reads (H5Dread) in a child process: a corrupt chunk that crashes
  // libhdf5 ends the reading with an error, not the process (hdf5_read_child.h).
  std::unique_ptr<detail::Hdf5ReadChild> reads_;
  std::string_view layout_;
  Hid file_ = -1;
  Hid x_ = -1, y_ = -1, t_ = -1, p_ = -1;  // column datasets, or t_ = the compound
  std::vector<Hid> float_columns_;         // open_float_columns's
  std::vector<std::string> float_names_;
  std::int64_t total_ = 0;
  std::int64_t file_bytes_ = 0;
  std::int64_t t_offset_us_ = 0;
  bool t_float_ = false;               // the time column is floating-point (read as doubles)
  std::int64_t t_unit_ns_ = 1000;      // ns per unit of the time column's values
  TableColumns table_{-1, -1, -1, -1};  // an N×4 table (t_ = the table) or none
  std::string table_name_;              // its dataset
  std::string column_names_[4];         // the column datasets x, y, t, p (for errors)
  std::optional<SensorSize> sensor_;
  std::int64_t next_ = 0;  // index of the first event not yet loaded
  std::vector<std::uint16_t> xs_, ys_;
  std::vector<std::int64_t> ts_;
  std::vector<std::int8_t> ps_;
  std::vector<CdRecord> records_;
  std::vector<double> doubles_;  // a table's rows, or a column of seconds, before conversion
  std::size_t chunk_size_ = 0;
  std::size_t chunk_pos_ = 0;
  std::optional<ReadError> error_;
  std::string unloadable_filter_;  // a dataset's filter this HDF5 cannot load, and where to get it (read errors say it)
};

}  // namespace evlife::io
