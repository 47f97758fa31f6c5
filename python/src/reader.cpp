// evlife.read / evlife.open / evlife.read_augmented / evlife.write: the io
// readers and writers, straight into and out of NumPy arrays (the C++ reader
// writes into the array's memory; the GIL is released while it runs).
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>

#include <algorithm>
#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "bindings.h"
#include "dtypes.h"
#include "errors.h"
#include "evlife/io/augmented_event_reader.h"
#include "evlife/io/augmented_event_writer.h"
#include "evlife/io/event_reader.h"
#include "evlife/io/sensor_size_from_data.h"
#include "evlife/io/write_error.h"
#include "options.h"

namespace evlife::python {
namespace {

constexpr std::size_t kReadBlock = 1 << 16;

// The keywords of each function (a misspelling of one is said so: refuse_keywords).
const std::vector<std::string_view> kReadKeywords = {"path", "sensor", "from_s", "to_s", "topic", "time_unit",
                                                     "polarity"};
const std::vector<std::string_view> kOpenKeywords = {"path",   "sensor", "chunk_events", "from_s",
                                                     "to_s",   "topic",  "time_unit",    "polarity"};
const std::vector<std::string_view> kReaderReadKeywords = {"max_events"};

py::object sensor_tuple(std::optional<SensorSize> s) {
  if (!s) return py::none();
  return py::make_tuple(s->width, s->height);
}

}  // namespace

py::dict skipped_kinds_dict(const std::vector<io::SkippedKindCount>& kinds) {
  py::dict d;
  for (const io::SkippedKindCount& k : kinds) d[py::str(std::string(k.kind))] = k.count;
  return d;
}


namespace {

// Every event of a reader; on a fault raises InputError carrying the events
// before it, on Ctrl-C evlife.Interrupted carrying those read.
py::array read_all(io::EventReader& reader, SignalCheck& signals) {
  std::vector<Event> events;
  std::optional<io::ReadError> fault;
  {
    ReleasedGil release;
    std::size_t good = 0;  // events.size() beyond it: a block being filled
    try {
      while (!signals.pending()) {
        events.resize(good + kReadBlock);
        const std::size_t n = reader.read(std::span(events.data() + good, kReadBlock));
        good += n;
        if (n == 0) break;
      }
    } catch (const io::ReadError& e) {
      fault.emplace(e);
    }
    events.resize(good);
  }
  const std::size_t n = events.size();
  py::array out = adopt(std::move(events), event_dtype());
  if (fault) raise_input_error(*fault, out);
  if (signals.pending_now()) {
    SignalCheck::raise("evlife.read: interrupted after " + std::to_string(n) + " events of " + reader.path() +
                           " (in .partial)",
                       out, n, py::none());
  }
  return out;
}

/// evlife.open(): a recording read chunk by chunk (bounded memory).
class Reader {
 public:
  Reader(const std::string& path, const io::ReaderOptions& options, std::size_t chunk_events)
      : chunk_events_(chunk_events), path_(path), options_(options) {
    if (chunk_events == 0) throw py::value_error("chunk_events must be at least 1");
    reader_ = io::open_event_reader(path, options);
  }

  /// The next chunk; at the end of a recording of which from_s / to_s or
  /// polarity selected no event, a RuntimeWarning as evlife.read's (once),
  /// attributed `stacklevel` frames up (1: the line that called read).
  py::array read(std::optional<std::size_t> max_events, int stacklevel = 1) {
    if (max_events == std::size_t{0})  // an empty chunk is the end of the recording
      throw py::value_error("max_events must be at least 1");
    const std::size_t n_max = max_events.value_or(chunk_events_);
    std::vector<Event> events;  // grows block by block: a large max_events costs nothing
    std::size_t n = 0;
    std::optional<io::ReadError> fault;
    bool closed = false, none_delivered = false;
    SignalCheck signals(/*long_call=*/n_max > kReadBlock);
    const bool locked = run_locked_unless_interrupted(mutex_, [&] {
      if (pending_) {  // a fault met after good events last time: raised now, once
        fault.swap(pending_);
      } else if (!reader_) {
        closed = true;
      } else {
        try {
          // Fill the chunk unless the stream ends (a reader may return less).
          while (n < n_max && !signals.pending()) {
            events.resize(n + std::min(n_max - n, kReadBlock));
            const std::size_t got = reader_->read(std::span(events.data() + n, events.size() - n));
            if (got == 0) break;
            n += got;
          }
        } catch (const io::ReadError& e) {
          if (n == 0) fault.emplace(e);  // else: the good events first, the fault next call
          else pending_.emplace(e);
        }
        delivered_ += n;
        none_delivered = delivered_ == 0;
      }
    });
    if (!locked) raise_while_waiting("evlife.Reader.read", adopt(std::vector<Event>{}, event_dtype()));
    if (closed) throw py::value_error("the reader is closed");
    if (fault) raise_input_error(*fault);
    events.resize(n);
    py::array chunk = adopt(std::move(events), event_dtype());
    // Ctrl-C: the events read are the exception's, the next read goes on after them.
    if (signals.pending_now()) {
      SignalCheck::raise("evlife.Reader.read: interrupted after " + std::to_string(n) +
                             " events of the chunk (in .partial; the next read goes on after them)",
                         chunk, n, py::none());
    }
    // The end of a recording of which the crop selected nothing: said once, as evlife.read says it.
    if (n == 0 && none_delivered && !warned_.exchange(true))
      warn_empty_crop("evlife.open", path_, options_, 0, stacklevel);
    return chunk;
  }

  py::array next(int stacklevel = 1) {
    py::array chunk = read(std::nullopt, stacklevel);
    if (chunk.shape(0) == 0) throw py::stop_iteration();
    return chunk;
  }

  void close() {
    if (!run_locked_unless_interrupted(mutex_, [&] { reader_.reset(); }))
      raise_while_waiting("evlife.Reader.close", py::none());
  }

  /// f(reader) under the lock that read() and close() take, the GIL released
  /// while waiting: a property read from another thread while one reads or
  /// closes used a freed reader (a segfault) or raced its counters. f returns
  /// plain C++ values; Python objects are made after, with the GIL.
  template <class F>
  auto query(F f) const {
    std::optional<decltype(f(std::declval<const io::EventReader&>()))> value;
    if (!run_locked_unless_interrupted(mutex_, [&] {
          if (reader_) value.emplace(f(*reader_));
        }))
      raise_while_waiting("evlife.Reader (reading a property)", py::none());
    if (!value) throw py::value_error("the reader is closed");
    return std::move(*value);
  }
  std::size_t chunk_events() const { return chunk_events_; }

 private:
  std::unique_ptr<io::EventReader> reader_;
  std::size_t chunk_events_;
  std::string path_;
  io::ReaderOptions options_;
  std::uint64_t delivered_ = 0;  // events returned so far
  std::atomic<bool> warned_{false};
  std::optional<io::ReadError> pending_;
  mutable std::timed_mutex mutex_;

  // Ctrl-C while another thread's call held the reader: nothing read.
  [[noreturn]] static void raise_while_waiting(const char* who, py::object partial) {
    raise_interrupted_while_waiting(who, "the reader", "nothing read, the next read goes on where it was",
                                    std::move(partial));
  }
};

// The sensor rule of every command (README, *Sensor size*): a size the file
// states wins over `sensor=`, which is for files that state none (it
// overrode a stated one: events refused as outside a smaller size, a larger
// one reported as the file's).
io::ReaderOptions with_stated_sensor(const std::string& path, io::ReaderOptions options) {
  if (!options.sensor) return options;
  io::ReaderOptions probe_options = options;
  probe_options.sensor.reset();
  if (const auto stated = io::stated_sensor_size(*io::open_unchecked_event_reader(path, probe_options), options.sensor))
    options.sensor = stated;
  return options;
}

/// io::open_augmented_reader(path), but a recording (stripes.mat, a .npy) that
/// it refused as "not an augmented CSV: the first line must be 'x,y,t,p,...'"
/// is said to be one, with what reads it.
std::unique_ptr<io::AugmentedEventReader> open_augmented_or_say_a_recording(const std::string& path) {
  try {
    return io::open_augmented_reader(path);
  } catch (const io::AugmentedColumnsError&) {  // evlife's output, damaged: its own message
    throw;
  } catch (const io::ReadError&) {
    if (io::names_augmented_bin(path)) throw;
    std::string format;
    bool recording_events = false;  // an empty file is no recording either
    try {
      const auto recording = io::open_unchecked_event_reader(path);
      format = std::string(recording->format_name());
      Event first;
      recording_events = recording->read(std::span(&first, 1)) > 0;
    } catch (const io::ReadError&) {
      recording_events = !format.empty();  // a recording's format, cut or corrupt further on
    }
    // Neither (or HDF5 events, which its reader names as such): the augmented readers' reason.
    if (!recording_events || format == "hdf5") throw;
    throw io::ReadError(path, 0, -1,
                        "a recording (" + format +
                            "), not evlife's output: evlife.read reads its events, evlife.process "
                            "estimates them; read_augmented reads the .bin, .csv or .h5 that `evlife "
                            "process -o` and evlife.write write");
  }
}

// Reader.read's max_events (None: chunk_events), and no other keyword.
std::optional<std::size_t> max_events_argument(const py::handle& max_events, const py::dict& kw) {
  refuse_keywords("evlife.Reader.read", kw, kReaderReadKeywords);
  return optional_int_argument<std::size_t>("evlife.Reader.read", "max_events", max_events, "events", 1);
}

}  // namespace

py::array read_events(const std::string& path, const io::ReaderOptions& options) {
  std::unique_ptr<io::EventReader> reader;
  std::optional<io::ReadError> fault;
  // Before the opening (a bag's index, a file's start): a Ctrl-C there is
  // evlife.Interrupted too, not a KeyboardInterrupt out of the next Python call.
  SignalCheck signals;
  {
    ReleasedGil release;
    const IoStopScope io_stop(signals);  // a NAME.db3.zstd's decompression
    try {
      reader = io::open_event_reader(path, with_stated_sensor(path, options));
    } catch (const io::ReadError& e) {
      fault.emplace(e);
    }
  }
  if (fault && signals.pending_now())
    SignalCheck::raise("evlife.read: interrupted while opening " + path + ": " + fault->what(),
                       adopt(std::vector<Event>{}, event_dtype()), 0, py::none());
  // A fault at open (a bag cut before its first message): no event before it,
  // an empty .partial as for a fault at the first event, not None.
  if (fault) raise_input_error(*fault, adopt(std::vector<Event>{}, event_dtype()));
  py::array events = read_all(*reader, signals);
  warn_empty_crop("evlife.read", path, options, static_cast<std::uint64_t>(events.shape(0)));
  warn_skipped_records("evlife.read", path, reader->skipped_record_count(), reader->skipped_record_kinds());
  return events;
}

void bind_reader(py::module_& m) {
  m.def(
      "read",
      [](const PathArgument& path, const py::object& sensor, const OptionalFloatArgument& from_s,
         const OptionalFloatArgument& to_s, const OptionalStrArgument& topic, const OptionalStrArgument& time_unit,
         const OptionalStrArgument& polarity, const py::kwargs& kw) {
        refuse_keywords("evlife.read", kw, kReadKeywords);
        const std::string file = path_argument("evlife.read", "path", path);
        const std::optional<SensorSize> size = optional_sensor_from_python(sensor);
        return read_events(file, reader_options("evlife.read", size, from_s, to_s, topic, time_unit, polarity));
      },
      py::arg("path"), py::arg("sensor") = py::none(), py::kw_only(), py::arg("from_s") = py::none(),
      py::arg("to_s") = py::none(), py::arg("topic") = py::none(), py::arg("time_unit") = py::none(),
      py::arg("polarity") = py::none(),
        R"(Read every event of a recording into a NumPy structured array.

Fields: t (int64, microseconds), x, y (uint16; x = 0 left, y = 0 top),
p (int8, +1 ON / -1 OFF), dtype evlife.EVENT_DTYPE. Every input format of
`evlife process` (sniffed from the content, else the extension).

sensor: (width, height) the events must fit in when the format states no size
(a size the file states wins, as for every command). from_s, to_s: only the events from from_s to to_s (exclusive)
seconds after the first event of the file, as `evlife process --from --to`;
HDF5 files (DSEC, Prophesee, evlife's) start there by a binary search on t,
without decoding the events before it. topic: a ROS bag's event topic (needed
when it has several; the error lists them), or an HDF5 file's camera (MVSEC
davis/right/events, M3ED prophesee/right; the left by default), or an .npz
archive's array of events, as --topic. time_unit: 's', 'ms', 'us' or 'ns', the
unit of a CSV/text, NumPy or HDF5 file's time column, as --time-unit
(default: its name's, its datetime64 type's, which refuses another, or its
HDF5 units attribute's, else seconds for fractions or floats, else us).
polarity: 'on' or 'off' reads only the ON or OFF events, as --polarity
('both', the default, reads every event). Raises FileNotFoundError for a missing file and
evlife.InputError (a ValueError) for an unknown format, corrupt or truncated
data, an event outside the sensor or a timestamp going backwards; its message
names the file, event index and byte offset, and its `partial` attribute
holds the events before the fault. A from_s / to_s or polarity that selects
no event is warned of (RuntimeWarning), as by the CLI; so are the format's
records that are not events (triggers, IMU samples, frames: skipped, counted).)");

  py::class_<Reader>(m, "Reader", R"(A recording read in chunks of bounded size (see evlife.open).

Iterating yields arrays of at most `chunk_events` events (evlife.EVENT_DTYPE)
until the end; memory stays bounded whatever the file size. On a fault the
good events come first, the next chunk raises evlife.InputError.)")
      .def("__reduce__",
           [](const Reader&) -> py::object {
             throw py::type_error(
                 "an evlife.Reader cannot be pickled (an open file): send the path, and evlife.open it in the task");
           })
      .def_property_readonly(
          "sensor",
          [](const Reader& r) {
            return sensor_tuple(r.query([](const io::EventReader& e) { return e.sensor_size(); }));
          },
          "(width, height) when the format states it (or sensor= was given), else None.")
      .def_property_readonly(
          "format",
          [](const Reader& r) {
            return r.query([](const io::EventReader& e) { return std::string(e.format_name()); });
          },
          "Short format name, e.g. 'mat', 'aedat2', 'evt3'.")
      .def_property_readonly(
          "layout",
          [](const Reader& r) {
            return r.query([](const io::EventReader& e) { return std::string(e.layout_name()); });
          },
          "Which of its format's layouts the file holds (HDF5: 'dsec', 'event_utils', 'prophesee', "
          "'mvsec', 'v2e', 'evlife'; .npy: 'structured' or the columns', 't,x,y,p'; .npz: also which "
          "array, 'structured, array events.npy', or 'arrays x.npy, ...'); '' where a format has one.")
      .def_property_readonly(
          "path",
          [](const Reader& r) {
            // As os.fsdecode gives it: a name that is not UTF-8 (surrogate escapes), as InputError.path.
            const std::string path = r.query([](const io::EventReader& e) { return e.path(); });
            return py::reinterpret_steal<py::object>(PyUnicode_DecodeFSDefault(path.c_str()));
          },
          "The recording's path, as os.fsdecode gives it.")
      .def_property_readonly("chunk_events", &Reader::chunk_events)
      .def_property_readonly(
          "bytes_consumed",
          [](const Reader& r) { return r.query([](const io::EventReader& e) { return e.bytes_consumed(); }); },
          "Bytes of the file consumed so far (approximate for compressed formats; 0 where the format "
          "cannot say: .npy, .npz).")
      .def_property_readonly(
          "skipped_records",
          [](const Reader& r) {
            return r.query([](const io::EventReader& e) { return e.skipped_record_count(); });
          },
          "Records of the format read so far that are not events (triggers, IMU samples, frames).")
      .def_property_readonly(
          "skipped_record_kinds",
          [](const Reader& r) {
            return skipped_kinds_dict(r.query([](const io::EventReader& e) { return e.skipped_record_kinds(); }));
          },
          "skipped_records by kind, {kind: count}, where the format tells them apart.")
      .def(
          "read",
          [](Reader& r, const OptionalIntArgument& max_events, const py::kwargs& kw) {
            return r.read(max_events_argument(max_events, kw));
          },
          py::arg("max_events") = py::none(),
          "The next chunk of at most max_events (default chunk_events) events; empty at the end (a from_s / to_s "
          "or polarity that selected no event is then warned of, as by evlife.read).")
      .def(
          "_read",
          [](Reader& r, const OptionalIntArgument& max_events, const py::kwargs& kw) {
            return r.read(max_events_argument(max_events, kw), 2);
          },
          py::arg("max_events") = py::none(), "Internal: read() for a wrapper (StreamReader): warnings at its caller.")
      .def(
          "_next", [](Reader& r) { return r.next(2); }, "Internal: __next__() for a wrapper (StreamReader).")
      .def("close", &Reader::close)
      .def("__iter__", [](py::object self) { return self; })
      .def("__next__", [](Reader& r) { return r.next(); })
      .def("__enter__", [](py::object self) { return self; })
      .def("__exit__", [](Reader& r, py::args) { r.close(); });

  m.def(
      "open",
      [](const PathArgument& path_arg, const py::object& sensor, const IntArgument& chunk_events_arg,
         const OptionalFloatArgument& from_s, const OptionalFloatArgument& to_s, const OptionalStrArgument& topic,
         const OptionalStrArgument& time_unit, const OptionalStrArgument& polarity, const py::kwargs& kw) {
        refuse_keywords("evlife.open", kw, kOpenKeywords);
        const std::string path = path_argument("evlife.open", "path", path_arg);
        const std::optional<SensorSize> size = optional_sensor_from_python(sensor);
        const auto chunk_events = int_argument<std::size_t>("evlife.open", "chunk_events", chunk_events_arg,
                                                            "events", 1);
        const io::ReaderOptions options =
            reader_options("evlife.open", size, from_s, to_s, topic, time_unit, polarity);
        SignalCheck signals;
        std::unique_ptr<Reader> reader;
        std::optional<io::ReadError> stopped;
        {
          ReleasedGil release;
          const IoStopScope io_stop(signals);  // a NAME.db3.zstd's decompression
          try {
            reader = std::make_unique<Reader>(path, with_stated_sensor(path, options), chunk_events);
          } catch (const io::ReadError& e) {
            if (!signals.pending()) throw;
            stopped = e;
          }
        }
        if (stopped) {
          SignalCheck::raise("evlife.open: interrupted while opening " + path + ": " + stopped->what(), py::none(), 0,
                             py::none());
        }
        return reader;
      },
      py::arg("path"), py::arg("sensor") = py::none(), py::arg("chunk_events") = 1 << 20, py::kw_only(),
      py::arg("from_s") = py::none(), py::arg("to_s") = py::none(), py::arg("topic") = py::none(),
      py::arg("time_unit") = py::none(), py::arg("polarity") = py::none(),
      R"(Open a recording for reading in chunks (recordings larger than memory).

Returns an evlife.Reader with .sensor ((width, height) or None), .format and
iteration over chunks of at most chunk_events events:

    with evlife.open("rec.aedat4") as r:
        for chunk in r:
            ...

from_s, to_s, topic, time_unit, polarity and errors as evlife.read.)");

  m.def(
      "read_augmented",
      [](const PathArgument& path_arg) {
        const std::string path = path_argument("evlife.read_augmented", "path", path_arg);
        std::unique_ptr<io::AugmentedEventReader> reader;
        std::vector<AugmentedEvent> events;
        std::optional<io::ReadError> fault;
        std::optional<SensorSize> sensor;
        std::size_t good = 0;  // events.size() beyond it: a block being filled
        SignalCheck signals;
        {
          ReleasedGil release;
          try {
            reader = open_augmented_or_say_a_recording(path);
            sensor = reader->sensor_size();
            while (!signals.pending()) {
              events.resize(good + kReadBlock);
              const std::size_t n = reader->read(std::span(events.data() + good, kReadBlock));
              good += n;
              if (n == 0) break;
            }
          } catch (const io::ReadError& e) {
            fault.emplace(e);
          }
          events.resize(good);
        }
        py::array out = adopt(std::move(events), augmented_dtype());
        if (fault) raise_input_error(*fault, reader ? py::object(out) : py::none());
        if (signals.pending_now()) {
          SignalCheck::raise("evlife.read_augmented: interrupted after " + std::to_string(good) + " events of " + path +
                                 " (in .partial)",
                             out, good, py::none());
        }
        return py::make_tuple(out, sensor_tuple(sensor));
      },
      py::arg("path"),
      R"(Read a file written by `evlife process` (.bin, .csv or .h5).

Returns (events, sensor): events in evlife.AUGMENTED_DTYPE, sensor
(width, height) as the .bin header or the .h5 attributes state it, None
for CSV. Ctrl-C: evlife.Interrupted with the events read in .partial.)");

  m.def(
      "write",
      [](const PathArgument& path_arg, const py::array& augmented, const py::object& sensor) {
        const std::string path = path_argument("evlife.write", "path", path_arg);
        if (!is_exact(augmented, augmented_dtype())) {
          throw py::type_error("write: expected a 1-D contiguous array of evlife.AUGMENTED_DTYPE");
        }
        const SensorSize s = sensor_from_python(sensor);
        const auto* data = static_cast<const AugmentedEvent*>(augmented.data());
        const auto n = static_cast<std::size_t>(augmented.shape(0));
        // Nothing is written that evlife.read_augmented and `evlife render` would refuse.
        const io::RecordFault bad = io::first_unreadable_record(std::span(data, n), s, INT64_MIN);
        if (bad.index < n) {
          raise_input_error(io::ReadError("augmented", -1, static_cast<std::int64_t>(bad.index),
                                          bad.what + "; nothing was written to " + path));
        }
        SignalCheck signals;
        std::size_t written = 0;
        std::optional<std::string> stopped;  // a FIFO output no reader opened or drained, stopped by Ctrl-C
        {
          ReleasedGil release;
          const IoStopScope io_stop(signals);
          try {
            auto writer = io::open_augmented_writer(path, s);
            while (written < n && !signals.pending()) {  // blocks: Ctrl-C is heard between them
              const std::size_t block = std::min(n - written, kReadBlock);
              writer->write(std::span(data + written, block));
              written += block;
            }
            writer->close();  // what was written reaches the disk, interrupted or not
          } catch (const io::WriteError& e) {
            if (!signals.pending()) throw;
            stopped = e.what();
          }
        }
        if (stopped) {
          SignalCheck::raise("evlife.write: interrupted: " + *stopped, py::none(), written, py::none());
        }
        if (written < n) {
          SignalCheck::raise("evlife.write: interrupted after " + std::to_string(written) + " of " +
                                 std::to_string(n) + " events; " + path + " holds the first " + std::to_string(written),
                             py::none(), written, py::int_(written));
        }
      },
      py::arg("path"), py::arg("augmented"), py::arg("sensor"),
      R"(Write augmented events as `evlife process -o` does: .bin (the binary format
of the README, 32-byte records), .csv or .h5, by extension. augmented: the
output of evlife.process, or any array with its fields (joined chunks, a
slice; prediction_error NaN where missing), as evlife.frame takes. Raises
OSError when the file cannot be written, TypeError for a field missing,
evlife.InputError (nothing written) for a record evlife.read_augmented would
refuse: polarity not +1/-1, outside `sensor`, time going backwards;
evlife.Interrupted on Ctrl-C, the file then holding the first
.events_written events (None where a FIFO's reader took nothing: the
message says how many bytes were not written).)");
}

}  // namespace evlife::python
