// `evlife info FILE`: what a recording holds, for every readable format:
// format, sensor size, event count (ON / OFF), time span, triggers and other
// skipped records, and for containers (ROS bags) every stream with its
// message type and count; for evlife's own outputs the lifetimes they hold.
// One pass over the events (constant memory).
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "arg_parser.h"
#include "command.h"
#include "command_start.h"
#include "evlife/io/augmented_event_reader.h"
#include "evlife/io/event_reader.h"
#include "exit_code.h"
#include "input_spool.h"
#include "lifetime_summary.h"
#include "stop_signals.h"

namespace evlife::cli::info_command {
namespace {

constexpr OptionSpec kOptions[] = {
    {"help", 'h', false, false}, kInputOptionSpec,
    kTopicOptionSpec, kTimeUnitOptionSpec, kPolarityOptionSpec, kFromOptionSpec, kToOptionSpec,
};

void print_help(std::FILE* out) {
  std::fprintf(out,
               "evlife info — what a recording holds\n"
               "\n"
               "Usage: evlife info FILE [--topic NAME] [--time-unit U] [--polarity on|off|both]\n"
               "                        [--from T] [--to T]\n"
               "\n"
               "Prints the format, the sensor size (stated by the file, else the range the\n"
               "events span), the number of events (ON / OFF), the first and last timestamp\n"
               "and the duration, the longest stretch without events (a timestamp outlier\n"
               "shows there), trigger and other skipped records, and for ROS bags every\n"
               "topic with its message type and count (the one read marked '*').\n"
               "For evlife's own outputs (.bin, .csv, .h5 with lifetimes: `evlife process -o`)\n"
               "also the lifetimes they hold: share labelled noise, lifetime percentiles,\n"
               "predictions and the pixels firing at >= %.0f Hz, as `evlife process`\n"
               "summarised them.\n"
               "Reads every event once (an output without a sensor size, the .csv, twice:\n"
               "the second time for the per-pixel counts over the span its events cover),\n"
               "in constant memory; corrupt data is reported after the figures of the\n"
               "events before it.\n"
               "\n"
               "Options:\n"
               "  -i, --input FILE   the FILE (also as the first argument).\n",
               BusyPixels::kMinRateHz);
  std::fputs((std::string(kInputOptionsHelp) + std::string(kCropOptionsHelp)).c_str(), out);
  std::fprintf(out,
               "  -h, --help         this text.\n"
               "\n"
               "Exit status: 0 done; 2 bad command line; 3 input error (corrupt data, or\n"
               "timestamps that go backwards: described in full, the first one named).\n"
               "\n"
               "Examples:\n"
               "  evlife info recording.aedat4\n"
               "  evlife info bag/ --topic /event_camera/events   # a ROS bag of several event topics\n"
               "  evlife info lifetimes.bin                        # output of evlife process\n");
}

std::string thousands(std::uint64_t v) {
  const std::string digits = std::to_string(v);
  std::string s;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) s += ',';
    s += digits[i];
  }
  return s;
}

// What every event file's description counts, one event at a time.
struct EventTally {
  std::uint64_t on = 0, off = 0;
  std::int64_t first = 0, last = 0;
  int max_x = -1, max_y = -1;
  bool ordered = true;
  std::uint64_t backwards = 0;  // events earlier than one before them (the other commands stop at the first)
  std::uint64_t first_backwards_index = 0;
  std::int64_t first_backwards_t_us = 0, first_backwards_after_us = 0;
  std::uint64_t longest_gap_us = 0;  // between events in file order: a timestamp outlier shows here
  std::int64_t longest_gap_after_us = 0;

  std::uint64_t count() const noexcept { return on + off; }

  void add(const Event& e) noexcept {
    if (on + off == 0) first = last = e.t_us;
    if (e.t_us < last) {
      if (ordered) {
        first_backwards_index = count();
        first_backwards_t_us = e.t_us;
        first_backwards_after_us = last;
      }
      ordered = false;
      ++backwards;
    }
    // Unsigned: a gap may span all of int64 (-2^63 .. 2^63 - 1).
    if (e.t_us > last && span_us(last, e.t_us) > longest_gap_us) {
      longest_gap_us = span_us(last, e.t_us);
      longest_gap_after_us = last;
    }
    last = std::max(last, e.t_us);
    first = std::min(first, e.t_us);
    (e.p > 0 ? on : off) += 1;
    max_x = std::max<int>(max_x, e.x);
    max_y = std::max<int>(max_y, e.y);
  }
};

void print_events(const EventTally& t, std::optional<SensorSize> stated, const std::string& guessed = {}) {
  if (stated) {
    std::printf("sensor     %dx%d (%s)\n", stated->width, stated->height,
                guessed.empty() ? "stated by the file" : guessed.c_str());
  } else if (t.max_x >= 0) {
    std::printf("sensor     not stated; the events span %dx%d (max x + 1, max y + 1)\n", t.max_x + 1, t.max_y + 1);
  } else {
    std::printf("sensor     not stated\n");
  }
  std::printf("events     %s (%s ON, %s OFF)\n", thousands(t.on + t.off).c_str(), thousands(t.on).c_str(),
              thousands(t.off).c_str());
  if (t.on + t.off > 0) {
    std::printf("time       %lld .. %lld us, duration %.6f s%s\n", static_cast<long long>(t.first),
                static_cast<long long>(t.last), seconds_between(t.first, t.last),
                t.ordered ? ""
                          : fmt::format(" (timestamps go backwards: {} events earlier than one before them, "
                                        "the first named below)",
                                        thousands(t.backwards))
                                .c_str());
    if (t.on + t.off == 1) {
      std::printf("gap        none: one event\n");
    } else {  // (no gap at all: every event at the first's time; "after t = 0" named none of them)
      std::printf("gap        longest without events %.6f s, after t = %lld us\n",
                  static_cast<double>(t.longest_gap_us) * 1e-6,
                  static_cast<long long>(t.longest_gap_us > 0 ? t.longest_gap_after_us : t.first));
    }
  }
}

// Every event of `reader` (up to a stop signal) into `tally` (when given)
// and `lifetimes`; the message of the read error that stopped it, if one did.
std::string read_augmented(io::AugmentedEventReader& reader, EventTally* tally, LifetimeSummary& lifetimes,
                           const StopRequest& stop) {
  std::vector<AugmentedEvent> batch(1 << 14);
  try {
    while (const std::size_t n = stop.requested() ? 0 : reader.read(batch)) {
      const std::span<const AugmentedEvent> got(batch.data(), n);
      if (tally != nullptr) {
        for (const AugmentedEvent& a : got) tally->add(a.event);
      }
      lifetimes.add(got);
    }
  } catch (const io::ReadError& e) {
    return e.what();
  }
  return {};
}

// After the description: exit 130 when a stop signal ended the reading (the
// description covers the events read), else 0.
int interrupted_exit(const StopRequest& stop, std::uint64_t events_read) {
  if (!stop.requested()) return kExitOk;
  std::fprintf(stderr, "evlife info: interrupted; the description covers the first %llu events\n",
               static_cast<unsigned long long>(events_read));
  return kExitInterrupted;
}

// An evlife output (.bin, or .csv with lifetime columns): the events, then the
// lifetimes as `evlife process` summarised them when it wrote the file. A file
// that states no sensor size (the CSV, a .bin `convert` wrote of events of no
// known sensor) is read a second time with the span its
// events cover as the sensor, for the pixels firing at hot-pixel rates.
int describe_augmented(const std::string& path, const std::string& shown, io::AugmentedEventReader& reader,
                       const StopRequest& stop) {
  EventTally tally;
  const std::optional<SensorSize> stated = reader.sensor_size();
  std::optional<LifetimeSummary> lifetimes(std::in_place, stated);
  const std::string fault = read_augmented(reader, &tally, *lifetimes, stop);
  if (const SensorSize spanned{tally.max_x + 1, tally.max_y + 1}; !stated && spanned.within_camera_limits()) {
    if (const auto again = io::open_if_augmented(path)) {
      lifetimes.emplace(spanned);
      read_augmented(*again, nullptr, *lifetimes, stop);  // stops where the first pass did (its fault is reported)
    }
  }
  std::printf("file       %s\n", shown.c_str());
  std::printf("format     %s (evlife's output: each event with its lifetime, velocity and prediction error)\n",
              std::string(reader.format_name()).c_str());
  print_events(tally, stated);
  std::printf("lifetimes  as estimated when the file was written\n");
  lifetimes->print_figures(stdout);
  if (!fault.empty()) {
    std::fprintf(stderr, "evlife info: %s\n", fault.c_str());
    return kExitInput;
  }
  return interrupted_exit(stop, tally.count());
}

int run_info(int argc, char** argv) {
  std::string path;
  io::ReaderOptions options;
  if (const auto done = start_command("info", argc, argv, print_help, [&] {
        const ParsedArgs a = parse_args(argc, argv, kOptions);
        if (a.positional.size() != 1) throw UsageError("expected one FILE");
        path = a.positional.front();
        options = parse_input_options(a);
        refuse_selection_of_augmented(options, path);
      })) {
    return *done;
  }
  std::optional<InputSpool> spool;  // FILE `-` or a pipe: read from a copy
  if (const auto done = spool_stream_input("info", path, true, spool)) return *done;
  // The description names the copy as well; messages name `path` as the stream (io::name_in_messages).
  const std::string shown = spool ? spool->stream() + " (a stream, read from its copy " + path + ")" : path;
  const StopRequest stop;  // Ctrl-C: the events read so far are described, the stream's copy removed
  // A fault at open: a stop or an option the format does not take as every command says them, else the file's.
  const auto open_fault = [&](const io::ReadError& e) -> int {
    if (stop.requested() || dynamic_cast<const io::OptionNotTaken*>(&e) != nullptr)
      return open_fault_exit("info", path, e);
    std::fprintf(stderr, "evlife info: %s\n", e.what());
    return kExitInput;
  };
  // evlife's own outputs first (as `render` reads them): their CSV would
  // otherwise pass for a plain x,y,t,p file and the .bin for no format.
  try {
    if (const auto augmented = io::open_if_augmented(path)) return describe_augmented(path, shown, *augmented, stop);
  } catch (const io::ReadError& e) {
    return open_fault(e);
  }
  std::unique_ptr<io::EventReader> reader;
  try {
    reader = io::open_unchecked_event_reader(path, options);
  } catch (const io::ReadError& e) {
    return open_fault(e);
  }
  std::vector<Event> batch(1 << 16);
  EventTally tally;
  std::string fault;
  std::string backwards;  // the first event earlier than one before it, as the checked readers name it
  try {
    while (const std::size_t n = stop.requested() ? 0 : reader->read(batch)) {
      for (std::size_t i = 0; i < n; ++i) tally.add(batch[i]);
      if (!tally.ordered && backwards.empty()) {  // offsets are known for the batch just read
        const auto index = static_cast<std::int64_t>(tally.first_backwards_index);
        backwards = io::ReadError(reader->path(), reader->byte_offset_of_event(index), index,
                                  fmt::format("timestamp goes backwards: {} us after {} us", tally.first_backwards_t_us,
                                              tally.first_backwards_after_us))
                        .what();
      }
    }
  } catch (const io::ReadError& e) {
    fault = e.what();
  }
  const std::string format(reader->format_name());
  std::printf("file       %s\n", shown.c_str());
  std::string description;
  for (const auto& f : io::known_event_formats())
    if (f.name == format) description = std::string(f.description);
  std::printf("format     %s (%s)\n", format.c_str(), description.c_str());
  if (const std::string_view layout = reader->layout_name(); !layout.empty())
    std::printf("layout     %.*s\n", static_cast<int>(layout.size()), layout.data());
  print_events(tally, reader->sensor_size(), reader->sensor_size_note());
  if (tally.on + tally.off == 0 && fault.empty() && !stop.requested()) warn_empty_crop("info", path, options);
  std::printf("triggers   %s\n", thousands(reader->trigger_count()).c_str());
  std::printf("skipped    %s records that are not events (triggers included)\n",
              thousands(reader->skipped_record_count()).c_str());
  if (const std::string kinds = io::skipped_kinds_text(*reader); !kinds.empty())
    std::printf("  by kind  %s\n", kinds.c_str());
  const auto streams = reader->streams();
  if (!streams.empty()) {
    std::printf("%s     %zu\n", format == "npz" ? "arrays" : "topics", streams.size());
    // HDF5: MVSEC's cameras (--topic); .npz: its arrays (--topic), their first dimension.
    const char* unit = format == "hdf5" ? "rows" : format == "npz" ? "rows" : "messages";
    for (const io::ContainerStream& s : streams) {
      std::printf("  %c %-32s %-40s %s %s\n", s.read ? '*' : ' ', s.name.c_str(), s.type.c_str(),
                  thousands(s.messages).c_str(), unit);
    }
  }
  if (!backwards.empty()) {  // described above, but every other command stops there: not a clean exit
    std::fprintf(stderr, "evlife info: %s (the first of %s; process, convert and render stop at it)\n",
                 backwards.c_str(), thousands(tally.backwards).c_str());
  }
  if (!fault.empty()) {
    std::fprintf(stderr, "evlife info: %s\n", fault.c_str());
    return kExitInput;
  }
  return backwards.empty() ? interrupted_exit(stop, tally.count()) : kExitInput;
}

}  // namespace

EVLIFE_REGISTER_COMMAND("info", "describe a recording: format, sensor, events, duration, topics", run_info);

}  // namespace evlife::cli::info_command
