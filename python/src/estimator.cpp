// evlife.LifetimeEstimator and evlife.process: the C++ estimator over NumPy
// arrays. The output array is allocated once and the estimator writes into it
// directly; the GIL is released while events are checked and estimated.
#include <pybind11/stl.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "bindings.h"
#include "dtypes.h"
#include "errors.h"
#include "event_columns.h"
#include "evlife/algo/lifetime_estimator.h"
#include "evlife/config/config.h"
#include "evlife/engine/prefetch_reader.h"
#include "evlife/engine/write_behind_writer.h"
#include "evlife/io/augmented_event_writer.h"
#include "evlife/io/event_reader.h"
#include "evlife/io/output_path.h"
#include "evlife/io/sensor_size_from_data.h"
#include "evlife/io/write_error.h"
#include "options.h"

namespace evlife::python {
namespace {

constexpr std::size_t kBlockEvents = 1 << 16;  // as `evlife process`

// The keywords of each function besides the estimator's (a misspelling of
// one is said so: resolve_options).
const std::vector<std::string_view> kEstimatorKeywords = {"sensor", "config"};
const std::vector<std::string_view> kProcessKeywords = {"input",  "sensor", "config",    "one_thread", "from_s",
                                                        "to_s",   "topic",  "time_unit", "polarity"};
const std::vector<std::string_view> kScanKeywords = {"input", "sensor", "config", "topic", "time_unit"};
const std::vector<std::string_view> kProcessFileKeywords = {"input", "output", "sensor",    "config",  "one_thread",
                                                            "from_s", "to_s",  "topic", "time_unit", "polarity"};

/// The estimator with what Python needs around it: the time of the last
/// event (order is checked across calls) and a lock (calls from several
/// threads run one at a time).
class Estimator {
 public:
  Estimator(const std::string& where, const py::object& sensor, const py::object& config,
            const py::dict& options)
      : Estimator(resolve_options(where, sensor, config, options)) {}
  explicit Estimator(ResolvedOptions resolved)
      : resolved_(std::move(resolved)), estimator_(resolved_.config.estimator) {}

  /// Checks `events` whole, then estimates them; on bad input raises
  /// InputError and leaves the state as it was. In blocks (chunks give the
  /// one-call result), Ctrl-C checked between them: evlife.Interrupted.
  py::array process(const py::handle& events) {
    const EventColumns cols = event_columns(events);
    py::array out(augmented_dtype(), std::vector<py::ssize_t>{static_cast<py::ssize_t>(cols.size)},
                  std::vector<py::ssize_t>{static_cast<py::ssize_t>(sizeof(AugmentedEvent))});
    auto* dst = static_cast<AugmentedEvent*>(out.mutable_data());
    EventCheck check;
    SignalCheck signals(/*long_call=*/cols.size > kBlockEvents);
    std::size_t processed = 0;
    const bool locked = run_locked_unless_interrupted(mutex_, [&] {
      check = check_events(cols, estimator_.options().sensor, last_t_us_);
      if (check.bad_index == SIZE_MAX) {
        std::vector<Event> block(check.convert ? std::min(cols.size, kBlockEvents) : 0);
        while (processed < cols.size && !(processed > 0 && signals.pending())) {
          const std::size_t n = std::min(kBlockEvents, cols.size - processed);
          if (!check.convert) {
            estimator_.process(std::span(cols.exact + processed, n), std::span(dst + processed, n));
            last_t_us_ = cols.exact[processed + n - 1].t_us;
          } else {
            convert_events(cols, processed, std::span(block.data(), n));
            estimator_.process(std::span<const Event>(block.data(), n), std::span(dst + processed, n));
            last_t_us_ = block[n - 1].t_us;
          }
          processed += n;
        }
      }
    });
    if (!locked) raise_while_waiting("process", out[py::slice(0, 0, 1)]);
    if (check.bad_index != SIZE_MAX) {
      raise_input_error(io::ReadError("events", -1, static_cast<std::int64_t>(check.bad_index),
                                      check.what + "; no event of this call was processed"));
    }
    if (processed < cols.size || signals.pending_now()) {
      signals.raise("interrupted after " + std::to_string(processed) + " of " + std::to_string(cols.size) +
                        " events; the estimator's state includes them: go on with events[" +
                        std::to_string(processed) + ":]",
                    out[py::slice(0, static_cast<py::ssize_t>(processed), 1)], processed, py::none());
    }
    return out;
  }

  void reset() {
    const bool locked = run_locked_unless_interrupted(mutex_, [&] {
      estimator_.reset();
      last_t_us_ = INT64_MIN;
    });
    if (!locked) raise_while_waiting("reset", py::none());
  }

  py::dict stats() {
    LifetimeStats s;
    const bool locked = run_locked_unless_interrupted(mutex_, [&] { s = estimator_.stats(); });
    if (!locked) raise_while_waiting("stats", py::none());
    py::dict d;
    d["events"] = s.events;
    d["noise"] = s.noise;
    d["noise_few_samples"] = s.noise_few_samples;
    d["noise_unsupported"] = s.noise_unsupported;
    d["noise_unresolved"] = s.noise_unresolved;
    d["predictions"] = s.predictions;
    d["followers"] = s.followers;
    for (const RejectionCounter& c : kRejectionCounters) d[c.name] = s.*c.count;  // time_backwards 0: process() raises first
    return d;
  }

  SensorSize sensor() const { return estimator_.options().sensor; }
  const config::Config& config() const { return resolved_.config; }

 private:
  // Ctrl-C while another thread's call held the estimator: nothing done.
  [[noreturn]] static void raise_while_waiting(const char* what, py::object partial) {
    raise_interrupted_while_waiting(std::string("evlife.LifetimeEstimator.") + what, "the estimator",
                                    "nothing done, its state as it was", std::move(partial));
  }

  ResolvedOptions resolved_;
  LifetimeEstimator estimator_;
  std::int64_t last_t_us_ = INT64_MIN;
  std::timed_mutex mutex_;
};

// What the sensor probe and scan read: the whole stream, read as `options`
// say (topic, time unit), without the crop (the events of a crop alone could
// fit a smaller sensor than the file's). The time unit was dropped: a CSV in
// epoch ns failed the scan with time_unit="ns" given.
io::ReaderOptions whole_stream(const io::ReaderOptions& options) {
  io::ReaderOptions whole = options;
  whole.sensor.reset();
  whole.from_us.reset();
  whole.to_us.reset();
  whole.polarity = io::PolarityFilter::both;
  return whole;
}

/// What one run over a file saw.
struct FileRun {
  SensorSize sensor;
  std::string format;
  std::uint64_t events = 0;
  std::uint64_t with_lifetime = 0;
  std::uint64_t skipped_records = 0;  // the format's non-event records (as the CLI's summary)
  std::vector<io::SkippedKindCount> skipped_kinds;
  std::optional<io::ReadError> fault;  // the events before it were handed to the sink
  bool interrupted = false;            // Ctrl-C: the events before were handed to the sink
  LifetimeStats stats;  // the estimator's, at the end (rejected(): the CLI summary's "rejected" line)
  std::string sensor_ignored;  // "sensor=(W, H)" or config='s size, where the file states another

  void note_skipped(const io::EventReader& reader) {  // at the end of the pass
    skipped_records = reader.skipped_record_count();
    skipped_kinds = reader.skipped_record_kinds();
  }
};

// `evlife process PATH [--from --to]` (the times of `crop`; its sensor is
// set here): the same sensor rule, reader, estimator and blocks;
// each block of augmented events goes to `sink`, then `on_sensor` has been
// called once before. Unless `one_thread`, the file is decoded ahead on a
// thread of its own (as `evlife process` without --one-thread: the same
// events, sooner). Runs without the GIL; stops between blocks on Ctrl-C.
template <class OnSensor, class Sink>
FileRun run_file(const std::string& path, std::optional<SensorSize> user, ResolvedOptions r,
                 io::ReaderOptions crop, bool one_thread, SignalCheck& signals, OnSensor&& on_sensor, Sink&& sink) {
  FileRun run;
  const auto probe = io::open_unchecked_event_reader(path, whole_stream(crop));
  if (const auto stated = io::stated_sensor_size(*probe, user)) {
    run.sensor = *stated;
    // As the CLI warns of --sensor (or a configured size) the file's own size overrules.
    const std::optional<SensorSize> asked = user ? user : r.sensor;
    if (asked && *asked != *stated)
      run.sensor_ignored = (user ? "sensor=(" : "config='s estimator.sensor (") + std::to_string(asked->width) +
                           ", " + std::to_string(asked->height) + ")";
  } else if (user) run.sensor = *user;  // --sensor
  else if (r.sensor) run.sensor = *r.sensor;  // estimator.sensor of the user's config file
  else run.sensor = io::sensor_size_from_data_until(path, whole_stream(crop), [&signals] { return signals.pending(); });
  if (signals.pending()) {  // the scan stopped early: its size is not the recording's, nothing is opened with it
    run.interrupted = true;
    return run;
  }
  crop.sensor = run.sensor;
  std::unique_ptr<io::EventReader> reader = io::open_event_reader(path, crop);
  run.format = std::string(reader->format_name());
  r.config.estimator.sensor = run.sensor;
  LifetimeEstimator estimator(r.config.estimator);  // std::invalid_argument: ValueError
  if (!one_thread) reader = std::make_unique<engine::PrefetchReader>(std::move(reader));
  on_sensor(run.sensor);
  std::vector<Event> in(kBlockEvents);
  std::vector<AugmentedEvent> out(kBlockEvents);
  for (;;) {
    if (run.events > 0 && signals.pending()) {
      run.interrupted = true;
      break;
    }
    std::size_t n = 0;
    try {
      n = reader->read(in);
    } catch (const io::ReadError& e) {
      run.fault.emplace(e);
      break;
    }
    if (n == 0) break;
    estimator.process(std::span<const Event>(in.data(), n), std::span(out.data(), n));
    for (std::size_t i = 0; i < n; ++i) run.with_lifetime += !out[i].is_noise();
    run.events += n;
    sink(std::span<const AugmentedEvent>(out.data(), n));
  }
  run.note_skipped(*reader);
  run.stats = estimator.stats();
  return run;
}

// The records of the format that are not events (triggers, IMU samples,
// frames), counted as the command line's summary counts them.
void add_skipped(py::dict& d, const FileRun& run) {
  d["skipped_records"] = run.skipped_records;
  d["skipped_record_kinds"] = skipped_kinds_dict(run.skipped_kinds);
}

// The events the estimator rejected (labelled noise), as process_file's
// "rejected" (evlife process prints them as its "rejected" line).
void add_rejected(py::dict& d, const FileRun& run) {
  py::dict rejected;
  for (const RejectionCounter& c : kRejectionCounters) {
    if (c.why != Rejection::time_backwards) rejected[c.name] = run.stats.*c.count;  // the file's run raises on it
  }
  d["rejected"] = rejected;
}

// evlife.process(PATH) returns the events alone: rejected ones are warned of
// (a RuntimeWarning; an exception where warnings are errors).
std::string rejected_warning(const std::string& function, const std::string& path, const LifetimeStats& stats) {
  if (stats.rejected() == 0) return {};
  return function + ": " + path + ": events rejected (labelled noise, lifetime 0): " + rejected_events_text(stats);
}

void warn_rejected(const std::string& path, const FileRun& run) {
  if (const std::string text = rejected_warning("evlife.process", path, run.stats); !text.empty())
    warn_at_callers_line(text);
}

// The CLI's warning that --sensor is ignored (the file states its size).
void warn_sensor_ignored(const std::string& function, const std::string& path, const FileRun& run) {
  if (run.sensor_ignored.empty()) return;
  warn_at_callers_line(function + ": " + run.sensor_ignored + " ignored: " + path + " states " +
                       std::to_string(run.sensor.width) + "x" + std::to_string(run.sensor.height) +
                       " (a size given is for formats that state none)");
}

// The warnings evlife.process gives of what a file's run dropped (rejected
// events, skipped records), from process_file's result: evlife.batch gives
// them at its caller's line, for the workers' runs.
std::vector<std::string> dropped_warnings(const std::string& function, const std::string& path, const py::dict& r) {
  // A key that is not there counts 0 (a result of an older worker, or a test's stand-in).
  const auto count_of = [](const py::dict& d, const char* key) {
    return d.contains(key) ? d[key].cast<std::uint64_t>() : std::uint64_t{0};
  };
  const auto dict_of = [&r](const char* key) { return r.contains(key) ? r[key].cast<py::dict>() : py::dict(); };
  std::vector<std::string> texts;
  LifetimeStats stats;
  const py::dict rejected = dict_of("rejected");
  for (const RejectionCounter& c : kRejectionCounters) stats.*c.count = count_of(rejected, c.name);
  if (std::string text = rejected_warning(function, path, stats); !text.empty()) texts.push_back(std::move(text));
  std::vector<std::string> names;  // kept alive for the views of `kinds`
  std::vector<io::SkippedKindCount> kinds;
  for (const auto& [kind, count] : dict_of("skipped_record_kinds")) {
    names.push_back(kind.cast<std::string>());
    kinds.push_back({{}, count.cast<std::uint64_t>()});
  }
  for (std::size_t k = 0; k < kinds.size(); ++k) kinds[k].kind = names[k];  // (names grew: views taken after)
  if (std::string text = skipped_records_warning(function, path, count_of(r, "skipped_records"), kinds);
      !text.empty())
    texts.push_back(std::move(text));
  return texts;
}

py::array process_file(const std::string& path, const py::object& sensor, const io::ReaderOptions& crop,
                       bool one_thread, const py::object& config, const py::dict& options) {
  // The sensor argument only counts when the format states none (as --sensor).
  const ResolvedOptions r = resolve_options("evlife.process", py::none(), config, options, kProcessKeywords);
  const std::optional<SensorSize> user = optional_sensor_from_python(sensor);
  std::vector<AugmentedEvent> out;
  FileRun run;
  SignalCheck signals;
  {
    ReleasedGil release;
    const IoStopScope io_stop(signals);  // a NAME.db3.zstd's decompression
    try {
      run = run_file(path, user, r, crop, one_thread, signals, [](SensorSize) {},
                     [&](std::span<const AugmentedEvent> block) {
        out.insert(out.end(), block.begin(), block.end());
      });
    } catch (const io::ReadError& e) {  // before the first event (opening, the sensor scan)
      run.fault = e;
    }
  }
  py::array result = adopt(std::move(out), augmented_dtype());  // .partial: empty, not None, as evlife.read's
  if (run.fault && signals.pending_now()) {  // the io call stopped by Ctrl-C
    signals.raise(path + ": interrupted: " + run.fault->what(), result, run.events, py::none());
  }
  if (run.fault) raise_input_error(*run.fault, result);
  if (run.interrupted || signals.pending_now()) {
    signals.raise(path + ": interrupted; the first " + std::to_string(run.events) + " events were processed (.partial)",
                  result, run.events, py::none());
  }
  warn_sensor_ignored("evlife.process", path, run);
  warn_rejected(path, run);
  warn_empty_crop("evlife.process", path, crop, run.events);
  warn_skipped_records("evlife.process", path, run.skipped_records, run.skipped_kinds);
  return result;
}

// `evlife process PATH -o OUTPUT`, in constant memory; unless `one_thread`
// decoded ahead and written behind, each on a thread of its own (the same
// bytes: `evlife process` without --one-thread).
py::dict process_to_file(const std::string& path, const std::string& output,
                         const py::object& sensor, const io::ReaderOptions& crop, bool one_thread,
                         const py::object& config, const py::dict& options) {
  const ResolvedOptions r = resolve_options("evlife.process_file", py::none(), config, options, kProcessFileKeywords);
  const std::optional<SensorSize> user = optional_sensor_from_python(sensor);
  if (const auto refusal = io::output_overwrites_input(path, output)) throw std::invalid_argument(*refusal);
  FileRun run;
  SignalCheck signals;
  bool opened = false;  // the output
  std::string stopped_write;  // the output's error where Ctrl-C stopped its wait (what it did not write)
  {
    ReleasedGil release;
    const IoStopScope io_stop(signals);  // a FIFO output no reader opens, a NAME.db3.zstd's decompression
    std::unique_ptr<io::AugmentedEventWriter> writer;
    try {
      run = run_file(
          path, user, r, crop, one_thread, signals,
          [&](SensorSize s) {
            writer = io::open_augmented_writer(output, s);
            opened = true;
            // Not behind a FIFO: its wait for a reader that stopped draining must run on this
            // thread, the one whose io waits hear Ctrl-C (IoStopScope).
            std::error_code fifo_error;
            if (!one_thread && !std::filesystem::is_fifo(output, fifo_error))
              writer = std::make_unique<engine::WriteBehindWriter>(std::move(writer));
          },
          [&](std::span<const AugmentedEvent> block) { writer->write(block); });
    } catch (const io::ReadError& e) {  // before the output was opened: nothing written, as the CLI
      run.fault = e;
    } catch (const io::WriteError& e) {
      if (!signals.pending()) throw;
      run.interrupted = true;  // the output's open or write, stopped by Ctrl-C
      if (opened) stopped_write = e.what();
    }
    try {
      if (writer) writer->close();  // everything before a fault reaches the disk
    } catch (const io::WriteError&) {
      if (!run.interrupted) throw;  // (a FIFO still undrained: its error was the stop's)
    }
  }
  if (run.fault && signals.pending_now()) run.interrupted = true;  // the io call stopped by Ctrl-C
  if (run.fault && !run.interrupted) {
    try {
      raise_input_error(*run.fault);
    } catch (py::error_already_set& error) {
      error.value().attr("events_written") = run.events;  // the output holds these
      throw;
    }
  }
  if (run.interrupted || signals.pending_now()) {  // as `evlife process` on SIGINT
    signals.raise(!opened                  ? "interrupted before " + output + " was opened; nothing written"
                  : stopped_write.empty() ? "interrupted; the first " + std::to_string(run.events) +
                                                " events were written to " + output
                                          : "interrupted while writing: " + stopped_write,
                  py::none(), run.events, py::int_(run.events));
  }
  warn_sensor_ignored("evlife.process_file", path, run);
  warn_empty_crop("evlife.process_file", path, crop, run.events);
  py::dict d;
  d["events"] = run.events;
  d["with_lifetime"] = run.with_lifetime;
  d["sensor"] = py::make_tuple(run.sensor.width, run.sensor.height);
  d["format"] = run.format;
  add_skipped(d, run);
  add_rejected(d, run);
  return d;
}

// The sensor `evlife process` would use for `path`, the time span and the
// event count: one pass (what a caller needs to cut a recording into slices).
py::dict scan_file(const std::string& path, const py::object& sensor, const py::object& config,
                   const std::optional<std::string>& topic, const std::optional<std::string>& time_unit) {
  const ResolvedOptions r = resolve_options("evlife.scan", py::none(), config, py::dict());
  const std::optional<SensorSize> user = optional_sensor_from_python(sensor);
  io::ReaderOptions source = reader_options(std::nullopt, std::nullopt, std::nullopt, topic, time_unit);
  std::int64_t first = 0, last = 0;
  std::uint64_t count = 0;
  FileRun run;
  SignalCheck signals;
  {
    ReleasedGil release;
    const IoStopScope io_stop(signals);  // a NAME.db3.zstd's decompression
    try {
      const auto probe = io::open_unchecked_event_reader(path, source);
      if (const auto stated = io::stated_sensor_size(*probe, user)) run.sensor = *stated;
      else if (user) run.sensor = *user;
      else if (r.sensor) run.sensor = *r.sensor;
      else run.sensor = io::sensor_size_from_data_until(path, source, [&signals] { return signals.pending(); });
      if (!signals.pending()) {  // (a scan stopped early found a size that is not the recording's)
        source.sensor = run.sensor;
        auto reader = io::open_event_reader(path, source);
        run.format = std::string(reader->format_name());
        std::vector<Event> in(kBlockEvents);
        while (!signals.pending()) {
          const std::size_t n = reader->read(in);  // a fault: InputError
          if (n == 0) break;
          if (count == 0) first = in[0].t_us;
          last = in[n - 1].t_us;
          count += n;
        }
        run.note_skipped(*reader);
      }
    } catch (const io::ReadError&) {
      if (!signals.pending()) throw;  // else: its decompression stopped by Ctrl-C
    }
  }
  if (signals.pending_now()) {
    SignalCheck::raise("evlife.scan: interrupted after " + std::to_string(count) + " events of " + path, py::none(),
                       count, py::none());
  }
  py::dict d;
  d["sensor"] = py::make_tuple(run.sensor.width, run.sensor.height);
  d["format"] = run.format;
  d["events"] = count;
  d["t_first"] = first;
  d["t_last"] = last;
  add_skipped(d, run);
  return d;
}

// The events of `path` with t in [t_begin, t_end) (no t_end: to the end, an
// event at INT64_MAX included), estimated by an estimator
// that started warmup_us earlier (its outputs before t_begin are dropped),
// written to `output` as they come (constant memory, as process_file): one
// slice of a recording processed in parallel with the others. On one thread:
// the slices are the parallelism. Its 'rejected' counts the events of
// [t_begin, t_end) alone: another slice's warm-up re-reads them.
py::dict process_time_range(const std::string& path, const std::string& output,
                            const py::object& sensor, std::int64_t t_begin, std::optional<std::int64_t> t_end,
                            std::int64_t warmup_us, bool skip_by_search, const py::object& config,
                            const std::optional<std::string>& topic, const std::optional<std::string>& time_unit,
                            const py::dict& options) {
  if (warmup_us < 0) throw py::value_error("warmup_us must be >= 0");
  ResolvedOptions r = resolve_options("evlife.batch.process_slices", py::none(), config, options);
  const SensorSize s = sensor_from_python(sensor);
  io::ReaderOptions source = reader_options(s, std::nullopt, std::nullopt, topic, time_unit);
  std::uint64_t events = 0, with_lifetime = 0;
  FileRun own;  // the rejected events of the slice's own range (its stats)
  {
    ReleasedGil release;
    auto reader = io::open_event_reader(path, source);
    r.config.estimator.sensor = s;
    LifetimeEstimator estimator(r.config.estimator);
    auto writer = io::open_augmented_writer(output, s);
    const std::int64_t start = t_begin < INT64_MIN + warmup_us ? INT64_MIN : t_begin - warmup_us;
    // Where the format can (HDF5), the events before the warm-up are not even
    // decoded; elsewhere the loop below drops them. process_slices' scan has
    // checked the time order this needs. (skip_by_search=False: the bench's
    // reference, the same events decoded and dropped.)
    if (skip_by_search) reader->skip_events_before(start);
    std::vector<Event> in(kBlockEvents);
    std::vector<AugmentedEvent> block(kBlockEvents);
    LifetimeStats warm_up_stats;
    bool done = false;
    while (!done) {
      const std::size_t n = reader->read(in);
      if (n == 0) break;
      std::size_t lo = 0, hi = n;
      while (lo < n && in[lo].t_us < start) ++lo;
      for (std::size_t i = lo; i < n; ++i) {
        if (t_end && in[i].t_us >= *t_end) {
          hi = i;
          done = true;
          break;
        }
      }
      if (hi <= lo) continue;
      std::size_t first = lo;  // the warm-up's events: estimated apart, their outputs dropped
      while (first < hi && in[first].t_us < t_begin) ++first;
      if (first > lo) {
        estimator.process(std::span<const Event>(in.data() + lo, first - lo), std::span(block.data(), first - lo));
        warm_up_stats = estimator.stats();  // the counts before the slice's own events
      }
      const std::span<AugmentedEvent> kept(block.data(), hi - first);
      estimator.process(std::span<const Event>(in.data() + first, hi - first), kept);
      for (const AugmentedEvent& e : kept) with_lifetime += !e.is_noise();
      events += kept.size();
      writer->write(kept);
    }
    writer->close();
    for (const RejectionCounter& c : kRejectionCounters)
      own.stats.*c.count = estimator.stats().*c.count - warm_up_stats.*c.count;
  }
  py::dict d;
  d["events"] = events;
  d["with_lifetime"] = with_lifetime;
  add_rejected(d, own);
  return d;
}

constexpr const char* kEstimatorDoc = R"(The lifetime estimator (Mueggler et al., ICRA 2015) over NumPy arrays.

    est = evlife.LifetimeEstimator(sensor=(240, 180), window_size=7)
    for chunk in evlife.open("rec.aedat4"):
        out = est.process(chunk)

sensor: (width, height). Keywords: every key of the `estimator:` section of
config/evlife.yaml (see evlife.estimator_options()), validated as the command
line validates --set estimator.KEY=VALUE (ValueError with its message;
TypeError for an unknown keyword). Keys not given take the values
`evlife process` uses: the documented default file, or config=PATH (a YAML
file, as --config).

process(events) takes any array with t, x, y, p fields (p as +1/-1, 0/1 or
bool) and returns evlife.AUGMENTED_DTYPE: t, x, y, p, lifetime (µs, 0 = noise),
vx, vy (px/s), prediction_error (µs, NaN = no prediction). The estimator keeps
its state across calls: processing in chunks gives exactly the result of one
call. The GIL is released while it runs; no per-event Python object is made.
RANSAC's draws are seeded per event from (seed, x, y, t, p), so the result is
the same on every run and machine, but shifting t (e.g. t - t[0]) changes the
draws as another seed would: keep the recording's times to match the CLI.)";

}  // namespace

void bind_estimator(py::module_& m) {
  py::class_<Estimator>(m, "LifetimeEstimator", kEstimatorDoc)
      // pickle's own message would be "cannot pickle 'PyCapsule' object".
      .def("__reduce__",
           [](const Estimator&) -> py::object {
             throw py::type_error(
                 "an evlife.LifetimeEstimator cannot be pickled (its surface holds every pixel's past): make one "
                 "inside the task, or send evlife.process / evlife.process_file to the workers");
           })
      .def(py::init([](const py::object& sensor, const py::object& config, const py::kwargs& kw) {
             ResolvedOptions r = resolve_options("evlife.LifetimeEstimator", sensor, config, kw, kEstimatorKeywords);
             if (!r.sensor)  // None built the library's default 128x128 unsaid
               throw py::type_error("evlife.LifetimeEstimator: sensor=(width, height) is required (or a config= "
                                    "file stating estimator.sensor)");
             // A large sensor's planes are allocated and zeroed (0.2 s at 1280x720, seconds at
             // 4096x4096): the other Python threads run meanwhile.
             ReleasedGil release;
             return std::make_unique<Estimator>(std::move(r));
           }),
           py::arg("sensor") = py::none(), py::kw_only(), py::arg("config") = py::none())
      .def(
          "process",
          [](Estimator& e, const py::handle& events, const py::kwargs& kw) {
            refuse_keywords("evlife.LifetimeEstimator.process", kw, {"events"});
            return e.process(events);
          },
          py::arg("events"),
           R"(Estimate lifetime and velocity of every event (in time order, also across calls).

Returns a new array of evlife.AUGMENTED_DTYPE, one row per input event, in
input order. Raises evlife.InputError (naming the event index) for an event
outside the sensor, a timestamp before the previous one or beyond +-2^62 us,
or a bad polarity; then nothing of this call is processed and the state is unchanged.)")
      .def("reset", &Estimator::reset, "Forget all history (keeps the options).")
      .def_property_readonly(
          "sensor", [](const Estimator& e) { return py::make_tuple(e.sensor().width, e.sensor().height); })
      .def_property_readonly(
          "options", [](const Estimator& e) { return options_dict(e.config()); },
          "The effective options, {keyword: value}.")
      .def_property_readonly("stats", &Estimator::stats,
                             "Counters: events, noise (and why: noise_few_samples, noise_unsupported, noise_unresolved), predictions, "
                             "followers, out_of_sensor, bad_polarity, time_out_of_range, time_backwards (0: process raises InputError first).");

  m.def(
      "process",
      [](const py::object& input, const py::object& sensor, const py::object& config,
         const BoolArgument& one_thread_arg, const OptionalFloatArgument& from_s_arg,
         const OptionalFloatArgument& to_s_arg, const OptionalStrArgument& topic_arg,
         const OptionalStrArgument& time_unit_arg, const OptionalStrArgument& polarity_arg,
         const py::kwargs& kw) -> py::array {
        const bool one_thread = bool_argument("evlife.process", "one_thread", one_thread_arg);
        const auto [from_s, to_s, topic, time_unit, polarity] =
            reader_arguments("evlife.process", from_s_arg, to_s_arg, topic_arg, time_unit_arg, polarity_arg);
        if (py::isinstance<py::str>(input) || py::isinstance<py::bytes>(input) || py::hasattr(input, "__fspath__")) {
          const std::string path = path_from_python(input);
          return process_file(path, sensor, reader_options(std::nullopt, from_s, to_s, topic, time_unit, polarity),
                              one_thread, config, kw);
        }
        if (py::hasattr(input, "read") && !py::hasattr(input, "dtype")) {  // not an array of events: "no field 't'" said less
          if (py::isinstance(input, py::module_::import("evlife._evlife").attr("Reader")))
            throw py::type_error("input: an evlife.Reader gives a recording chunk by chunk; give the file's path, or "
                                 "feed its chunks to one evlife.LifetimeEstimator (for chunk in reader: "
                                 "estimator.process(chunk))");
          throw py::type_error("input: a file object; give its path (or an array with t, x, y, p fields)");
        }
        if (from_s || to_s)
          throw py::value_error("from_s / to_s choose the events of a file; select an array's with a mask on its t");
        if (topic) throw py::value_error("topic chooses the stream of a file; an array has one");
        if (time_unit) throw py::value_error("time_unit is a file's; an array's t is in microseconds");
        if (polarity) throw py::value_error("polarity chooses the events of a file; select an array's with a mask on its p");
        // The command line's rule: sensor=, else the configured estimator.sensor
        // (config=; the events' own size replaced it), else the events' size.
        ResolvedOptions r = resolve_options("evlife.process", sensor, config, kw, kProcessKeywords);
        if (!r.sensor) {
          // Within 1..kMaxSensorSide; an event beyond it is named as the command line names it in a
          // file that states no sensor (the size clamped to it was named, as if the user had given it).
          const EventColumns cols = event_columns(input);
          if (const std::size_t i = first_beyond_any_camera(cols); i != SIZE_MAX) {
            raise_input_error(io::ReadError("events", -1, static_cast<std::int64_t>(i),
                                            event_position_text(cols, i) + " is beyond any camera (at most " +
                                                std::to_string(kMaxSensorSide) +
                                                " px a side) and no sensor= is given: a corrupt record?; no event "
                                                "of this call was processed"));
          }
          const SensorSize d = sensor_from_events(cols);
          r.config.estimator.sensor = SensorSize{std::max(d.width, 1), std::max(d.height, 1)};
        }
        std::unique_ptr<Estimator> estimator;
        {
          ReleasedGil release;  // as LifetimeEstimator(): its planes are allocated without the GIL
          estimator = std::make_unique<Estimator>(std::move(r));
        }
        return estimator->process(input);
      },
      py::arg("input"), py::arg("sensor") = py::none(), py::kw_only(),
      py::arg("config") = py::none(), py::arg("one_thread") = false, py::arg("from_s") = py::none(),
      py::arg("to_s") = py::none(), py::arg("topic") = py::none(), py::arg("time_unit") = py::none(),
      py::arg("polarity") = py::none(),
      R"(Lifetime and velocity of every event of a recording or an array: `evlife process`.

input: a path (every format of `evlife process`) or an array with t, x, y, p
fields. Returns evlife.AUGMENTED_DTYPE, bit-identical to the records of
`evlife process INPUT -o OUT.bin` with the same options.

sensor: (width, height) when the format states none (as --sensor); without
it estimator.sensor of config= when it sets one, else the smallest sensor
holding every event. Keywords and config=: as evlife.LifetimeEstimator. A recording is decoded ahead on a thread of its
own while the estimator runs (the same result, sooner); one_thread=True keeps
everything on the calling thread (as --one-thread; for one process per core).
from_s, to_s (a path only): the events from from_s to to_s (exclusive) seconds
after the first event, as --from / --to; the estimator starts at from_s, and
an HDF5 file is not decoded before it (evlife.read). topic (a path only): a ROS
bag's event topic, an HDF5 file's camera (MVSEC, M3ED) or an .npz array, as --topic;
time_unit (a path only): as --time-unit (evlife.read); polarity (a path
only): 'on' or 'off' processes only those events, as --polarity.
Errors: FileNotFoundError, evlife.InputError (with .partial: the augmented
events before the fault, as the CLI writes them; an array's event beyond
+-2^62 us too), ValueError for bad options. Events of a recording that the
estimator rejects (labelled noise; the CLI summary's "rejected" line) are
warned of with a RuntimeWarning that counts them; so is a from_s / to_s or
polarity that selects no event (as the CLI's warning), and so are the
records of a recording that are not events (triggers, IMU samples, frames).)");

  m.def(
      "process_file",
      [](const py::object& input, const py::object& output, const py::object& sensor,
         const py::object& config, const BoolArgument& one_thread_arg, const OptionalFloatArgument& from_s,
         const OptionalFloatArgument& to_s, const OptionalStrArgument& topic,
         const OptionalStrArgument& time_unit, const OptionalStrArgument& polarity,
         const py::kwargs& kw) {
        const bool one_thread = bool_argument("evlife.process_file", "one_thread", one_thread_arg);
        const std::string in = path_from_python(input), out = path_from_python(output);
        return process_to_file(in, out, sensor,
                               reader_options("evlife.process_file", std::nullopt, from_s, to_s, topic, time_unit,
                                              polarity),
                               one_thread, config, kw);
      },
      py::arg("input"), py::arg("output"), py::arg("sensor") = py::none(), py::kw_only(),
      py::arg("config") = py::none(), py::arg("one_thread") = false, py::arg("from_s") = py::none(),
      py::arg("to_s") = py::none(), py::arg("topic") = py::none(), py::arg("time_unit") = py::none(),
      py::arg("polarity") = py::none(),
      R"(`evlife process INPUT -o OUTPUT` in constant memory: the same file, byte for byte.

OUTPUT: .bin, .csv or .h5. Returns {'events', 'with_lifetime', 'sensor',
'format', 'skipped_records', 'skipped_record_kinds', 'rejected'} (the format's
records that are not events, e.g. triggers, IMU samples: a count, and a count
per kind where the format tells them apart; 'rejected': {'out_of_sensor',
'bad_polarity', 'time_out_of_range'}, the events the estimator labelled noise
unexamined, the CLI summary's "rejected" line). On bad input the events before the fault
are written, then evlife.InputError is raised (as the CLI exits 3) with
.events_written: how many. The input is decoded ahead
and the output written behind, each on a thread of its own (CSV formatting
and HDF5's deflate cost as much as the estimator); one_thread=True runs all
on the calling thread (evlife.batch does: one file per core). Other arguments
as evlife.process.)");

  m.def(
      "_dropped_warnings",
      [](const std::string& function, const py::handle& path, const py::dict& result) {
        py::list texts;  // a file name that is not UTF-8 as os.fsdecode gives it
        for (const std::string& t : dropped_warnings(function, path_from_python(path), result)) {
          PyObject* text = PyUnicode_DecodeUTF8(t.data(), static_cast<Py_ssize_t>(t.size()), "surrogateescape");
          if (text == nullptr) throw py::error_already_set();
          texts.append(py::reinterpret_steal<py::str>(text));
        }
        return texts;
      },
      py::arg("function"), py::arg("path"), py::arg("result"),
      "Internal: the warnings evlife.process gives of rejected events and skipped records, from process_file's "
      "result (evlife.batch gives them for its workers' runs).");
  m.def(
      "_check_reader_options",
      [](const OptionalFloatArgument& from_s, const OptionalFloatArgument& to_s,
         const OptionalStrArgument& time_unit, const OptionalStrArgument& polarity, const std::string& where) {
        reader_options(where, std::nullopt, from_s, to_s, py::none(), time_unit, polarity);
      },
      py::arg("from_s") = py::none(), py::arg("to_s") = py::none(), py::arg("time_unit") = py::none(),
      py::arg("polarity") = py::none(), py::kw_only(), py::arg("where") = "evlife.batch",
      "ValueError unless from_s / to_s / time_unit / polarity are valid (as evlife.process checks them).");

  m.def(
      "_refuse_overwriting_input",
      [](const py::object& input, const py::object& output) {
        if (const auto refusal = io::output_overwrites_input(path_from_python(input), path_from_python(output)))
          throw py::value_error(*refusal);
      },
      py::arg("input"), py::arg("output"),
      "ValueError when output names the input file (through links, or folders its path creates), as\n"
      "process_file and the command line refuse it.");

  m.def(
      "_check_options",
      [](const std::string& where, const std::vector<std::string>& own_keywords, const py::object& config,
         const py::kwargs& kw) {
        const std::vector<std::string_view> own(own_keywords.begin(), own_keywords.end());
        (void)resolve_options(where, py::none(), config, kw, own);
      },
      py::arg("where"), py::arg("own_keywords"), py::kw_only(), py::arg("config") = py::none(),
      "TypeError/ValueError unless the keywords are estimator options, as LifetimeEstimator checks them, named as\n"
      "`where`() (evlife.batch's functions); one near a name of own_keywords is said to be its misspelling.");

  m.def(
      "_check_bool",
      [](const std::string& where, const std::string& name, const py::object& value) {
        (void)bool_argument(where, name.c_str(), value);
      },
      py::arg("where"), py::arg("name"), py::arg("value"),
      "TypeError unless value is True or False (Python's or NumPy's bool), as evlife.process checks one_thread,\n"
      "named as `where`(): `name` (evlife.batch's flags).");
  m.def(
      "_check_str",
      [](const std::string& where, const std::string& name, const py::object& value) {
        (void)str_argument(where, name.c_str(), value);
      },
      py::arg("where"), py::arg("name"), py::arg("value"), "TypeError unless value is a str, named as `where`(): `name`.");

  m.def(
      "_check_sensor", [](const py::object& sensor) { (void)sensor_from_python(sensor); }, py::arg("sensor"),
      "TypeError/ValueError unless sensor is a camera's (width, height), as LifetimeEstimator checks it\n"
      "(without making one: up to 1.4 GB for the largest).");

  m.def(
      "scan",
      [](const py::object& input, const py::object& sensor, const py::object& config,
         const OptionalStrArgument& topic, const OptionalStrArgument& time_unit, const py::kwargs& kw) {
        refuse_keywords("evlife.scan", kw, kScanKeywords);
        const std::string path = path_argument("evlife.scan", "input", input);
        const auto topic_name = optional_str_argument("evlife.scan", "topic", topic);
        const auto unit = optional_str_argument("evlife.scan", "time_unit", time_unit);
        return scan_file(path, sensor, config, topic_name, unit);
      },
      py::arg("input"), py::arg("sensor") = py::none(), py::kw_only(),
      py::arg("config") = py::none(), py::arg("topic") = py::none(), py::arg("time_unit") = py::none(),
      R"(One pass over a recording: {'sensor' (the one `evlife process` uses), 'format',
'events', 't_first', 't_last' (µs), 'skipped_records', 'skipped_record_kinds'}
(as evlife.process_file). topic, time_unit and errors as evlife.read.)");

  m.def(
      "_process_time_range",
      [](const py::object& input, const py::object& output, const py::object& sensor,
         std::int64_t t_begin, std::optional<std::int64_t> t_end, std::int64_t warmup_us, bool skip_by_search,
         const py::object& config, const std::optional<std::string>& topic,
         const std::optional<std::string>& time_unit, const py::kwargs& kw) {
        return process_time_range(path_from_python(input), path_from_python(output), sensor, t_begin,
                                  t_end, warmup_us, skip_by_search, config, topic, time_unit, kw);
      },
      py::arg("input"), py::arg("output"), py::arg("sensor"), py::arg("t_begin"), py::arg("t_end"),
      py::arg("warmup_us"), py::kw_only(), py::arg("skip_by_search") = true,
      py::arg("config") = py::none(), py::arg("topic") = py::none(), py::arg("time_unit") = py::none(),
      "Internal (evlife.batch.process_slices): the events with t in [t_begin, t_end) (t_end None: no\n"
      "end) written to\n"
      "output (.bin), the estimator started warmup_us before t_begin; {'events', 'with_lifetime', 'rejected'}\n"
      "('rejected' as process_file's, of the events in [t_begin, t_end) only).");
}

}  // namespace evlife::python
