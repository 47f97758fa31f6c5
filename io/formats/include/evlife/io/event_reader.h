// Streaming event readers: constant memory, any file size. Formats are
// sniffed from the header (or the extension where the format has none).
//
// Coordinate convention of every reader: x = 0 is the left column, y = 0 the
// TOP row (as libcaer delivers DVS128 data over USB). Readers of formats with
// another origin convert (e.g. jAER AEDAT 2.0 is bottom-left: y is flipped;
// MATLAB .mat files are 1-based: 1 is subtracted).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "evlife/algo/event.h"

namespace evlife::io {

/// A read failure: names the file and where (byte offset and/or index of
/// the event at fault; -1 when unknown). what() contains all of it.
class ReadError : public std::runtime_error {
 public:
  ReadError(const std::string& path, std::int64_t byte_offset, std::int64_t event_index,
            const std::string& what);
  const std::string& path() const noexcept { return path_; }
  std::int64_t byte_offset() const noexcept { return byte_offset_; }
  std::int64_t event_index() const noexcept { return event_index_; }
  /// What went wrong, without the path and the location (what() has them).
  const std::string& reason() const noexcept { return reason_; }

 private:
  std::string path_;
  std::string reason_;
  std::int64_t byte_offset_;
  std::int64_t event_index_;
};

/// A reader option (`topic`, `time_unit`) that the file's format does not
/// take: the caller's choice is at fault, not the file (the CLI exits 2, as
/// for any flag that has nothing to act on; Python raises it as InputError).
class OptionNotTaken : public ReadError {
 public:
  using ReadError::ReadError;
};

/// A stream of a container file (a ROS bag's topic, an MVSEC file's camera), for `evlife info`.
struct ContainerStream {
  std::string name;            ///< e.g. "/dvs/events"
  std::string type;            ///< e.g. "dvs_msgs/msg/EventArray"
  std::uint64_t messages = 0;  ///< message count (an HDF5 table: its rows)
  bool read = false;           ///< the stream this reader delivers
};

/// Records of one kind that a reader skipped (not events), e.g. "imu6" or
/// "aps-sample"; `kind` names static text.
struct SkippedKindCount {
  std::string_view kind;
  std::uint64_t count = 0;
};

class EventReader;
/// reader.skipped_record_kinds() as "kind N, kind N" (empty when the format
/// does not tell its skipped records apart): for the commands' summaries.
std::string skipped_kinds_text(const EventReader& reader);
std::string skipped_kinds_text(const std::vector<SkippedKindCount>& kinds);
/// "(non-event records of the format: kind N, ...)", and with the count in
/// front, "N (...)": the summaries' line for reader.skipped_record_count() > 0.
std::string skipped_records_note(const EventReader& reader);
std::string skipped_records_text(const EventReader& reader);

class EventReader {
 public:
  virtual ~EventReader() = default;

  /// Fills `out` with up to out.size() events, in file order, and returns how
  /// many; 0 means end of stream. On corrupt or truncated data the events
  /// decoded before the fault are returned first; the call after throws
  /// ReadError (so nothing good is lost). Whole events are written (their
  /// reserved bytes zero): `out` may hold anything before (UninitializedArray).
  virtual std::size_t read(std::span<Event> out) = 0;

  /// Sensor size when the format states it (or the caller did, see
  /// ReaderOptions::sensor).
  virtual std::optional<SensorSize> sensor_size() const = 0;

  /// Short format name, e.g. "mat", "rpg-text", "aedat2".
  virtual std::string_view format_name() const = 0;

  virtual const std::string& path() const = 0;

  /// Records in the file that are not events and were skipped on purpose
  /// (e.g. AEDAT 2.0 special/external events). Shown to the user.
  virtual std::uint64_t skipped_record_count() const { return 0; }

  /// When sensor_size() is not stated by the file but guessed by the reader
  /// (v2e's AEDAT 2.0 names no sensor): how, for the user; "" when stated.
  virtual std::string sensor_size_note() const { return {}; }

  /// External trigger events seen so far (part of skipped_record_count(),
  /// never mixed into the events).
  virtual std::uint64_t trigger_count() const { return 0; }

  /// skipped_record_count() split by kind (only kinds seen, in a fixed order
  /// per format); empty when the format does not tell them apart.
  virtual std::vector<SkippedKindCount> skipped_record_kinds() const { return {}; }

  /// The streams of a container (every topic of a ROS bag); empty for
  /// single-stream formats.
  virtual std::vector<ContainerStream> streams() const { return {}; }

  /// Bytes of the file consumed so far (for progress display; approximate
  /// for compressed formats). 0 when unknown.
  virtual std::uint64_t bytes_consumed() const { return 0; }
  /// For a format whose clock wraps: what else a step back in time may be (a
  /// gap longer than half the clock's range), for the error's message; empty
  /// for the others.
  virtual std::string clock_wrap_note() const { return {}; }
  /// Which of a format's layouts the file holds (HDF5: "v2e", "mvsec", …),
  /// for `evlife info`; empty where a format has one.
  virtual std::string_view layout_name() const { return {}; }

  /// Byte offset in the file of event `event_index` (counted from 0 over the
  /// whole stream), valid for the events returned by the most recent read();
  /// -1 when the format cannot say (e.g. compressed data).
  virtual std::int64_t byte_offset_of_event(std::int64_t event_index) const {
    (void)event_index;
    return -1;
  }

  /// Before the first read(): moves past the events with t below `t_us`
  /// without decoding them, where the format can find them (HDF5: a binary
  /// search on t), and returns how many it passed (the index of the next
  /// event, which errors then name). Other readers, and a reader that has
  /// already been read from, pass nothing and return 0: the caller drops the
  /// early events as it reads them. Needs the events in time order (a checked
  /// pass over the file shows it); the events passed are not checked.
  virtual std::int64_t skip_events_before(std::int64_t t_us) {
    (void)t_us;
    return 0;
  }

  /// Before the first read(): the first event's time, where the format can
  /// read it without decoding a block (HDF5: one value of t). --from counts
  /// from it, and skip_events_before then starts there. nullopt otherwise
  /// (and for an empty or unreadable file: read() reports those).
  virtual std::optional<std::int64_t> first_event_time_us() const { return std::nullopt; }
};

/// Which polarities a reader delivers.
enum class PolarityFilter { both, on, off };
/// "on", "off", "both" (--polarity, Python's polarity=); nullopt for other text.
std::optional<PolarityFilter> parse_polarity_filter(std::string_view text);

/// What open_event_reader checks on top of decoding.
struct ReaderOptions {
  ReaderOptions() = default;
  // (A constructor, not aggregate initialization: fields can be added
  // without touching every caller.)
  ReaderOptions(std::optional<SensorSize> sensor_size, bool time_order)
      : sensor(sensor_size), require_time_order(time_order) {}

  /// Sensor the events must fit in; overrides what the format states. When
  /// neither says, coordinates are not bounds-checked (see
  /// sensor_size_from_data.h to infer one).
  std::optional<SensorSize> sensor;
  /// Timestamps going backwards are an error (the estimator needs order).
  bool require_time_order = true;
  /// Containers with several streams (ROS bags): the topic to read; empty =
  /// the only event topic (an error lists them when there are several).
  std::string topic;
  /// CSV/text layouts of other tools (format "csv") and NumPy files ("npy",
  /// "npz"): the unit of the time column, "s", "ms", "us" or "ns"; empty =
  /// from the header or field name (or a datetime64 type's, which refuses
  /// another), else seconds when the values are fractions, else µs.
  std::string time_unit;
  /// Cropping at the source (--from/--to): only events with
  /// first + from_us <= t < first + to_us, where `first` is the time of the
  /// file's first event; reading stops at the first event at or after the end.
  std::optional<std::int64_t> from_us;
  std::optional<std::int64_t> to_us;
  /// --polarity: only ON or only OFF events.
  PolarityFilter polarity = PolarityFilter::both;

  /// --to not after --from (the first event, 0, when --from is not given):
  /// nothing would be read. The command line and Python refuse it (each in
  /// its own words).
  bool crop_is_empty() const noexcept { return to_us && *to_us <= from_us.value_or(0); }

  bool filters() const noexcept {
    return from_us.has_value() || to_us.has_value() || polarity != PolarityFilter::both;
  }
};

/// Opens `path`, sniffing its format, and wraps the reader so that
/// coordinates outside the sensor and timestamps going backwards raise
/// ReadError (index of the event, byte offset when known) after the events
/// before it were delivered. Throws ReadError for a missing or unreadable
/// file or an unknown format (the message lists the known ones).
std::unique_ptr<EventReader> open_event_reader(const std::string& path,
                                               const ReaderOptions& options = {});

/// Same as open_event_reader(path, {sensor}).
std::unique_ptr<EventReader> open_checked_event_reader(const std::string& path,
                                                       std::optional<SensorSize> sensor);

/// The decoder alone, without the checks above (format errors still throw).
std::unique_ptr<EventReader> open_unchecked_event_reader(const std::string& path);
std::unique_ptr<EventReader> open_unchecked_event_reader(const std::string& path,
                                                         const ReaderOptions& options);

/// A readable format: short name (as format_name()) and a one-line description.
struct EventFormatInfo {
  std::string_view name;
  std::string_view description;
};
/// Every format open_event_reader knows, in sniffing order.
std::vector<EventFormatInfo> known_event_formats();

}  // namespace evlife::io
