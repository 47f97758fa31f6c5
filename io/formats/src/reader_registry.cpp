#include "reader_registry.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <filesystem>
#include <system_error>
#include <vector>

#include "checked_event_reader.h"
#include "cropping_event_reader.h"
#include "evlife_bin_magic.h"
#include "input_file.h"
#include "prophesee_header.h"
#include "size_checking_event_reader.h"

namespace evlife::io {
namespace detail {

std::span<const ReaderFormat* const> reader_formats() {
#define EVLIFE_READER_FORMAT(id) &id##_format,
  static const ReaderFormat* const table[] = {
#include "reader_formats.def"
  };
#undef EVLIFE_READER_FORMAT
  return table;
}

bool has_extension(std::string_view path, std::string_view ext) {
  if (path.size() < ext.size()) return false;
  const std::string_view tail = path.substr(path.size() - ext.size());
  return std::equal(tail.begin(), tail.end(), ext.begin(), [](char a, char b) {
    return std::tolower(static_cast<unsigned char>(a)) == std::tolower(static_cast<unsigned char>(b));
  });
}

}  // namespace detail

std::vector<EventFormatInfo> known_event_formats() {
  std::vector<EventFormatInfo> formats;
  for (const detail::ReaderFormat* f : detail::reader_formats())
    formats.push_back({f->name, f->description});
  return formats;
}

namespace {

std::unique_ptr<EventReader> open_as(const detail::ReaderFormat& f, const std::string& path,
                                     const ReaderOptions& options) {
  const std::string format(f.name);
  const auto takes = [&f](std::string_view option) { return f.options_taken.find(option) != std::string_view::npos; };
  if (!options.topic.empty() && !takes("topic")) {
    throw OptionNotTaken(path, -1, -1, "--topic chooses a stream of a ROS bag, MCAP or HDF5 file or an array of an .npz; "
                                  "this " + format + " file has one stream");
  }
  if (!options.time_unit.empty() && !takes("time-unit")) {
    throw OptionNotTaken(path, -1, -1, "--time-unit gives the time column's unit of CSV/text, NumPy and HDF5 files; "
                                  "this " + format + " file has its own");
  }
  return f.open_with_options != nullptr ? f.open_with_options(path, options) : f.open(path);
}

}  // namespace

std::unique_ptr<EventReader> open_unchecked_event_reader(const std::string& path) {
  return open_unchecked_event_reader(path, ReaderOptions{});
}

namespace {

std::unique_ptr<EventReader> open_decoder(const std::string& path, const ReaderOptions& options);

}  // namespace

std::unique_ptr<EventReader> open_unchecked_event_reader(const std::string& path,
                                                         const ReaderOptions& options) {
  std::unique_ptr<EventReader> reader = detail::SizeCheckingEventReader::wrap(open_decoder(path, options), path);
  if (!options.filters()) return reader;
  return std::make_unique<detail::CroppingEventReader>(std::move(reader), options);
}

namespace {

std::unique_ptr<EventReader> open_decoder(const std::string& path, const ReaderOptions& options) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    for (const detail::ReaderFormat* f : detail::reader_formats()) {
      if (f->claims_directory != nullptr && f->claims_directory(path)) return open_as(*f, path, options);
    }
    throw ReadError(path, -1, -1, "a directory, and not a ROS 2 bag folder (no metadata.yaml or .db3 files)");
  }
  std::array<std::byte, detail::kSniffBytes> head{};
  std::size_t head_size = 0;
  {
    const detail::InputFile file(path);  // throws "cannot open" for a missing file
    head_size = file.read_at(0, head);
  }
  const std::span<const std::byte> head_view(head.data(), head_size);
  const detail::ReaderFormat* by_extension = nullptr;
  for (const detail::ReaderFormat* f : detail::reader_formats()) {
    const detail::SniffResult r = f->sniff(head_view, path);
    if (r == detail::SniffResult::by_content) return open_as(*f, path, options);
    if (r == detail::SniffResult::by_extension && by_extension == nullptr) by_extension = f;
  }
  if (by_extension != nullptr) return open_as(*by_extension, path, options);
  // A Prophesee RAW file of an EVT version no reader decodes: say so rather
  // than "unknown format".
  if (const auto header = parse_prophesee_header(head_view); header && !header->evt_version().empty()) {
    throw ReadError(path, -1, -1,
                    "Prophesee RAW EVT " + header->evt_version() +
                        ": evlife decodes EVT 2.0, 2.1 and 3.0 only; record in one of those, or convert the file with "
                        "Metavision's metavision_file_to_csv (evlife reads its x,y,p,t CSV)");
  }
  const std::string_view head_text(reinterpret_cast<const char*>(head.data()), head_size);
  if (head_text.starts_with("MATLAB 7.3 MAT-file")) {  // MATLAB's save -v7.3: HDF5 behind a 512-byte header
    throw ReadError(path, 0, -1,
                    "a MATLAB v7.3 MAT-file (HDF5 inside): evlife reads MAT v5 files (N×4 'events', rows x y p t); "
                    "save it in MATLAB with save(FILE, 'events', '-v7')");
  }
  if (head_text.starts_with(detail::kAugmentedBinMagic)) {
    throw ReadError(path, 0, -1, std::string(detail::kAugmentedBinIsNoRecording));
  }
  if (detail::named_like_augmented_bin(path)) throw ReadError(path, 0, -1, detail::not_augmented_bin_reason(head_text));
  std::string known;
  for (const detail::ReaderFormat* f : detail::reader_formats())
    known += "\n  " + std::string(f->name) + ": " + std::string(f->description);
  throw ReadError(path, -1, -1,
                  head_size == 0 ? "empty file, not a known event format; known formats:" + known
                                 : "unknown event file format; known formats:" + known);
}

}  // namespace

std::optional<PolarityFilter> parse_polarity_filter(std::string_view text) {
  if (text == "on") return PolarityFilter::on;
  if (text == "off") return PolarityFilter::off;
  if (text == "both") return PolarityFilter::both;
  return std::nullopt;
}

std::unique_ptr<EventReader> open_event_reader(const std::string& path,
                                               const ReaderOptions& options) {
  // Checked before cropped: an event that --from or --polarity drops is
  // checked still (a step back or a pixel outside the sensor is an error,
  // not a silent drop), and errors name the file's event index and offset.
  std::unique_ptr<EventReader> raw = detail::SizeCheckingEventReader::wrap(open_decoder(path, options), path);
  const std::optional<SensorSize> sensor = options.sensor ? options.sensor : raw->sensor_size();
  auto checked = std::make_unique<detail::CheckedEventReader>(std::move(raw), sensor, options.require_time_order);
  if (!options.filters()) return checked;
  return std::make_unique<detail::CroppingEventReader>(std::move(checked), options);
}

std::unique_ptr<EventReader> open_checked_event_reader(const std::string& path,
                                                       std::optional<SensorSize> sensor) {
  return open_event_reader(path, ReaderOptions{sensor, true});
}

}  // namespace evlife::io
