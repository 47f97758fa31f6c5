// `evlife convert IN OUT`: rewrites a recording in another format, e.g. to
// check a decode against one's own tools or to hand events to h5py users.
// Streams batch by batch (constant memory); on bad input writes and flushes
// everything before the fault, then exits non-zero.
#include <cstdio>
#include <exception>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "arg_parser.h"
#include "command.h"
#include "command_start.h"
#include "evlife/engine/prefetch_reader.h"
#include "evlife/io/augmented_event_reader.h"
#include "evlife/io/augmented_event_writer.h"
#include "evlife/io/output_path.h"
#include "evlife/io/event_reader.h"
#include "evlife/io/event_writer.h"
#include "evlife/io/hdf5_writer.h"
#include "evlife/io/stream_copy_name.h"
#include "exit_code.h"
#include "input_spool.h"
#include "stop_signals.h"

namespace evlife::cli::convert_command {
namespace {

constexpr std::size_t kBatchEvents = 1 << 16;

constexpr OptionSpec kOptions[] = {
    {"sensor", 0, true, false},
    {"output", 'o', true, false},
    kInputOptionSpec,
    {"unchecked", 0, false, false},
    {"quiet", 'q', false, false},
    {"one-thread", 0, false, false},
    {"help", 'h', false, false},
    kTopicOptionSpec, kTimeUnitOptionSpec, kPolarityOptionSpec, kFromOptionSpec, kToOptionSpec,
};

void print_help(std::FILE* out) {
  std::fprintf(out,
      "evlife convert — rewrite an event recording in another format\n"
      "\n"
      "Usage: evlife convert INPUT OUTPUT [--sensor WxH] [--unchecked] [--quiet] [--one-thread]\n"
      "       evlife convert [-i] INPUT -o OUTPUT ...\n"
      "\n"
      "INPUT: any event recording evlife reads (sniffed from the content, else the\n"
      "extension):\n");
  for (const auto& f : io::known_event_formats()) {
    std::fprintf(out, "  %-14.*s %.*s\n", static_cast<int>(f.name.size()), f.name.data(),
                 static_cast<int>(f.description.size()), f.description.data());
  }
  std::fprintf(out,
      "or an augmented file written by `evlife process` (.csv, .bin or .h5).\n"
      "\n"
      "OUTPUT, chosen by its extension:\n"
      "  .txt         RPG text, one event per line 't x y p' (t in seconds, 6 decimals,\n"
      "               p 1/0); augmented input loses its lifetime/velocity columns.\n"
      "  .h5 .hdf5    HDF5, one dataset per field: x, y (uint16, px), t (int64, µs),\n"
      "               p (int8, +1/-1), and for augmented input lifetime (µs), vx, vy\n"
      "               (px/s), prediction_error (µs, NaN = none); units in attributes,\n"
      "               sensor size (where the input states one, or --sensor) in the\n"
      "               root attributes width/height. In Python:\n"
      "                 import h5py; f = h5py.File('OUT.h5'); t = f['t'][:]\n"
      "  .csv .bin    augmented events (only from augmented input; for a recording\n"
      "               use `evlife process INPUT -o OUT.bin`).\n"
      "\n"
      "Options:\n"
      "  -i, --input FILE, -o, --output FILE  INPUT and OUTPUT, as the two arguments.\n"
      "  --sensor WxH   sensor size to check coordinates against (and to store in\n"
      "                 HDF5) when the format does not state one.\n"
      "  --unchecked    write events exactly as decoded: no check of coordinates\n"
      "                 against the sensor or of time order.\n"
      "%s"
      "  -q, --quiet    no summary.\n"
      "  --one-thread   decode and write on one thread. By default a recording is\n"
      "                 decoded ahead on a thread of its own while the output is\n"
      "                 written: the same file, sooner (decompressing AEDAT 4 or HDF5\n"
      "                 and writing text or deflated HDF5 each take their time).\n"
      "  -h, --help     this text.\n"
      "\n"
      "Bad input (missing file, unknown format, truncated or corrupt data, and unless\n"
      "--unchecked coordinates outside the sensor or time going backwards) stops with\n"
      "a message naming the file and the event index / byte offset; the events before\n"
      "the fault are written and flushed.\n"
      "\n"
      "Exit status: 0 done; 2 bad command line; 3 input error; 4 output error;\n"
      "             130 interrupted (the events before the stop written).\n"
      "\n"
      "Examples:\n"
      "  evlife convert recording.aedat4 recording.h5\n"
      "  evlife convert evt3_sample.raw events.txt\n"
      "  evlife convert lifetimes.bin lifetimes.h5     # output of evlife process\n",
      (std::string(kInputOptionsHelp) + std::string(kCropOptionsHelp)).c_str());
}

struct Outcome {
  unsigned long long read = 0;
  unsigned long long written = 0;
  bool stopped = false;  // a stop signal: the events before it were written
  std::optional<std::string> input_fault;
  std::optional<std::string> output_fault;
};

// Copies batches from `read` to `write` until the end, a fault or a stop
// signal; closes the writer.
template <typename Record, typename Reader, typename Writer>
Outcome copy_all(Reader& reader, Writer& writer, const StopRequest& stop) {
  Outcome o;
  std::vector<Record> batch(kBatchEvents);
  while (true) {
    if (stop.requested()) {
      o.stopped = true;
      break;
    }
    std::size_t n = 0;
    try {
      n = reader.read(batch);
    } catch (const io::ReadError& e) {
      o.input_fault = e.what();
      break;
    }
    if (n == 0) break;
    o.read += n;
    try {
      writer.write(std::span<const Record>(batch.data(), n));
    } catch (const io::WriteError& e) {
      o.output_fault = e.what();
      break;
    }
    o.written += n;
  }
  try {
    writer.close();  // flushes: everything before a fault reaches the disk
  } catch (const io::WriteError& e) {
    if (!o.output_fault) o.output_fault = e.what();
  }
  return o;
}

// Augmented records as plain events (for .txt output of augmented input).
template <typename AugmentedReader>
class EventsOfAugmented {
 public:
  explicit EventsOfAugmented(AugmentedReader& reader) : reader_(reader) {}
  std::size_t read(std::span<Event> out) {
    buffer_.resize(out.size());
    const std::size_t n = reader_.read(buffer_);
    for (std::size_t i = 0; i < n; ++i) out[i] = buffer_[i].event;
    return n;
  }

 private:
  AugmentedReader& reader_;
  std::vector<AugmentedEvent> buffer_;
};

int report(const Outcome& o, const std::string& input, const std::string& output,
           const std::string& what, bool quiet) {
  if (o.output_fault) {  // what the file holds, the writer's error says (output_file.h)
    return output_fault_exit("convert", *o.output_fault, " (" + std::to_string(o.read) + " events read before it)");
  }
  if (!quiet) {
    std::fprintf(stdout, "evlife convert: %s -> %s: %llu %s written\n", io::name_in_messages(input).c_str(),
                 output.c_str(), o.written, what.c_str());
  }
  if (o.input_fault) {
    std::fprintf(stderr,
                 "evlife convert: input error: %s\n"
                 "evlife convert: the %llu events before the fault were written to %s\n",
                 o.input_fault->c_str(), o.written, output.c_str());
    return kExitInput;
  }
  if (o.stopped) {
    std::fprintf(stderr, "evlife convert: interrupted; the first %llu events were written to %s\n", o.written,
                 output.c_str());
    return kExitInterrupted;
  }
  return kExitOk;
}

// Augmented records checked against the sensor (width 0: any; the .bin
// reader checks its own): the records before the first outside it, then a
// ReadError naming its index.
class SensorCheckedAugmented {
 public:
  SensorCheckedAugmented(io::AugmentedEventReader& reader, SensorSize sensor) : reader_(reader), sensor_(sensor) {}
  std::size_t read(std::span<AugmentedEvent> out) {
    if (fault_) throw *fault_;
    const std::size_t n = reader_.read(out);
    const io::RecordFault bad = io::first_unreadable_record(out.first(n), sensor_, INT64_MIN);
    if (bad.index < n) {
      fault_.emplace(reader_.path(), -1, static_cast<std::int64_t>(delivered_ + bad.index), bad.what);
      if (bad.index == 0) throw *fault_;
    }
    delivered_ += bad.index;
    return bad.index;
  }

 private:
  io::AugmentedEventReader& reader_;
  SensorSize sensor_;
  std::uint64_t delivered_ = 0;
  std::optional<io::ReadError> fault_;
};

int convert_augmented(std::unique_ptr<io::AugmentedEventReader> reader, const std::string& input,
                      const std::string& output, std::optional<SensorSize> sensor_arg, bool quiet,
                      const StopRequest& stop) {
  // --sensor for a file that states none: checked and stored, as for a
  // recording's events (it was dropped); a stated size wins, with a warning.
  const std::optional<SensorSize> stated = reader->sensor_size();
  if (stated && sensor_arg) warn_sensor_flag_ignored("convert", *sensor_arg, input, *stated);
  const SensorSize sensor = stated.value_or(sensor_arg.value_or(SensorSize{}));
  SensorCheckedAugmented checked(*reader, sensor);
  try {
    if (has_extension(output, {".txt"})) {
      auto writer = io::open_event_writer(output);
      EventsOfAugmented events(checked);
      return report(copy_all<Event>(events, *writer, stop), input, output,
                    "events (lifetime/velocity columns dropped)", quiet);
    }
    auto writer = io::open_augmented_writer(output, sensor);
    return report(copy_all<AugmentedEvent>(checked, *writer, stop), input, output, "augmented events", quiet);
  } catch (const io::WriteError& e) {
    return output_fault_exit("convert", e.what());
  }
}

int convert_events(const std::string& input, const std::string& output,
                   std::optional<SensorSize> sensor_arg, const io::ReaderOptions& input_options,
                   bool unchecked, bool one_thread, bool quiet, const StopRequest& stop) {
  std::unique_ptr<io::EventReader> reader;
  std::optional<SensorSize> sensor;
  try {
    if (unchecked) {
      reader = io::open_unchecked_event_reader(input, input_options);
      sensor = reader->sensor_size() ? reader->sensor_size() : sensor_arg;
    } else {
      const auto probe = io::open_unchecked_event_reader(input, input_options);
      sensor = probe->sensor_size() ? probe->sensor_size() : sensor_arg;
      io::ReaderOptions checked = input_options;
      checked.sensor = sensor;
      reader = io::open_event_reader(input, checked);
    }
  } catch (const io::ReadError& e) {
    return open_fault_exit("convert", input, e);
  }
  // After the input opened: a missing or corrupt input is that input error, not
  // advice to process a file that cannot be read.
  if (has_extension(output, {".csv", ".bin"})) {
    std::fprintf(stderr,
                 "evlife convert: %s: .csv and .bin hold augmented events (lifetime, velocity):\n"
                 "  run `evlife process %s -o %s` for those;\n"
                 "  convert writes a recording's plain events to .txt or .h5 (see --help)\n",
                 output.c_str(), InputSpool::as_argument(input).c_str(), output.c_str());
    return kExitUsage;
  }
  if (sensor_arg) warn_sensor_flag_ignored("convert", *sensor_arg, input, *sensor);  // a stated size wins
  std::unique_ptr<io::EventWriter> writer;
  try {
    writer = io::open_event_writer(output, sensor);
  } catch (const io::WriteError& e) {
    return output_fault_exit("convert", e.what());
  }
  if (!one_thread) reader = std::make_unique<engine::PrefetchReader>(std::move(reader));
  const Outcome o = copy_all<Event>(*reader, *writer, stop);
  const std::string format(reader->format_name());
  std::string what = "events (" + format;
  if (sensor) what += ", sensor " + std::to_string(sensor->width) + "x" + std::to_string(sensor->height);
  what += ")";
  const int code = report(o, input, output, what, quiet);
  if (o.written == 0 && code == kExitOk) warn_empty_crop("convert", input, input_options);
  if (!quiet && reader->skipped_record_count() > 0)
    std::fprintf(stdout, "  skipped records: %s\n", io::skipped_records_text(*reader).c_str());
  return code;
}

int convert(int argc, char** argv) {
  std::string input;
  std::string output;
  std::optional<SensorSize> sensor;
  bool unchecked = false;
  bool quiet = false;
  bool one_thread = false;
  io::ReaderOptions input_options;
  if (const auto done = start_command("convert", argc, argv, print_help, [&] {
    const ParsedArgs a = parse_args(argc, argv, kOptions);
    std::vector<std::string> files = a.positional;  // INPUT OUTPUT, or INPUT -o OUTPUT
    if (const auto o = a.value("output")) files.push_back(*o);
    if (files.size() != 2) throw UsageError("expected INPUT and OUTPUT (or -o OUTPUT)");
    input = files[0];
    output = files[1];
    if (const auto s = a.value("sensor")) sensor = parse_sensor_size(*s);
    unchecked = a.has("unchecked");
    input_options = parse_input_options(a);
    refuse_selection_of_augmented(input_options, input);
    quiet = a.has("quiet");
    one_thread = a.has("one-thread");
    if (!has_extension(output, {".txt", ".h5", ".hdf5", ".csv", ".bin"})) {
      throw UsageError("OUTPUT " + output + ": expected a .txt, .h5, .csv or .bin file name");
    }
    if (const auto refusal = io::output_overwrites_input(input, output)) throw UsageError(*refusal);
  })) {
    return *done;
  }
  std::optional<InputSpool> spool;  // INPUT `-` or a pipe: read from a copy
  if (const auto done = spool_stream_input("convert", input, quiet, spool)) return *done;
  // Ctrl-C: the output closed with the events before it (an .h5 killed
  // unclosed opens nowhere), the stream's copy removed.
  const StopRequest stop;
  // Output of `evlife process` converts as augmented events: a .bin by its
  // name (its reader's error for one that is not), else by content (stdin's
  // copy has no extension); a .csv of other tools is read as events.
  std::unique_ptr<io::AugmentedEventReader> augmented;
  try {
    augmented = io::open_if_augmented(input);
  } catch (const io::ReadError& e) {
    return open_fault_exit("convert", input, e);
  }
  if (augmented) {
    // Nothing to act on: evlife's output is read whole, on one thread.
    if (unchecked || one_thread) {
      const char* flags = unchecked && one_thread ? "--unchecked and --one-thread"
                          : unchecked               ? "--unchecked"
                                                    : "--one-thread";
      std::fprintf(stderr, "evlife convert: warning: %s ignored: %s is evlife's output (checked as it is read)\n",
                   flags, io::name_in_messages(input).c_str());
    }
    return convert_augmented(std::move(augmented), input, output, sensor, quiet, stop);
  }
  return convert_events(input, output, sensor, input_options, unchecked, one_thread, quiet, stop);
}

}  // namespace

EVLIFE_REGISTER_COMMAND("convert", "rewrite a recording in another format (.txt, .h5; augmented .csv, .bin)",
                        convert);

}  // namespace evlife::cli::convert_command
