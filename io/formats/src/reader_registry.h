// Private: the table of readable formats used by open_event_reader.
//
// HOW TO ADD A FORMAT (one line): implement, in io/formats/src/<name>_reader.cpp,
//     namespace evlife::io::detail {
//     extern const ReaderFormat <name>_format;   // (declared by the .def line)
//     const ReaderFormat <name>_format{"name", "description", &sniff_fn, &open_fn};
//     }
// (open_with_options / claims_directory: optional, see ReaderFormat)
// and add `EVLIFE_READER_FORMAT(<name>)` to io/formats/src/reader_formats.def. Nothing
// else changes: declarations and the table are generated from that list.
// (Self-registration by static initializers is avoided on purpose: the linker
// drops unreferenced objects of a static library, and the format would vanish.)
#pragma once

#include <cstddef>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "evlife/io/event_reader.h"

namespace evlife::io::detail {

/// How sure a format is that a file is its own.
enum class SniffResult {
  no,            ///< not this format
  by_extension,  ///< only the file name suggests it (formats without magic)
  by_content,    ///< the header / magic bytes match
};

struct ReaderFormat {
  std::string_view name;         ///< = EventReader::format_name()
  std::string_view description;  ///< one line, listed in "unknown format" errors
  /// `head` = the first bytes of the file (up to kSniffBytes, fewer if the
  /// file is shorter); `path` for the extension. Must not throw.
  SniffResult (*sniff)(std::span<const std::byte> head, std::string_view path);
  /// Opens the file; throws ReadError on failure. (nullptr when
  /// open_with_options is set.)
  std::unique_ptr<EventReader> (*open)(const std::string& path);
  /// For formats that take options (e.g. a bag's topic); used when set.
  std::unique_ptr<EventReader> (*open_with_options)(const std::string& path,
                                                    const ReaderOptions& options) = nullptr;
  /// For formats stored as a directory: true when `path` (a directory) is
  /// one of theirs. Must not throw.
  bool (*claims_directory)(const std::string& path) = nullptr;
  /// The selection open_with_options reads beyond every format's (crop,
  /// polarity, sensor): "topic", "time-unit" or both ("topic, time-unit").
  /// Another given is refused (ReadError), not ignored.
  std::string_view options_taken = {};
};

inline constexpr std::size_t kSniffBytes = 4096;

/// A sniffed `head` shorter than kSniffBytes is the whole file: its last line
/// is whole even without '\n' (else it may be cut by the sniff window).
inline bool head_is_whole_file(std::span<const std::byte> head) noexcept { return head.size() < kSniffBytes; }

#define EVLIFE_READER_FORMAT(id) extern const ReaderFormat id##_format;
#include "reader_formats.def"
#undef EVLIFE_READER_FORMAT

/// The table, in the order of reader_formats.def. The first format sniffing
/// by_content wins; else the first by_extension; else "unknown format".
std::span<const ReaderFormat* const> reader_formats();

/// "true if `path` ends with `ext`" (ASCII case-insensitive), for sniffers.
bool has_extension(std::string_view path, std::string_view ext);

}  // namespace evlife::io::detail
