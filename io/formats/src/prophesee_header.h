// The `%` text header shared by Prophesee RAW (EVT 2.0 / 2.1 / 3.0) and DAT files:
// lines starting with '%', ending at `% end` or at the first line that does
// not start with '%'. Keys are the first word after "% ".
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "evlife/algo/event.h"

namespace evlife::io {

class ChunkedFile;

struct PropheseeHeader {
  std::vector<std::pair<std::string, std::string>> fields;  ///< key, rest of line
  std::int64_t size_bytes = 0;  ///< offset of the first byte after the header

  /// Value of the first line with this key (ASCII case-insensitive).
  std::optional<std::string_view> find(std::string_view key) const;

  /// "2.0", "3.0", "2.1" from `% evt 3.0` or `% format EVT3;...`, else from
  /// the camera plugin (Gen3 → 2.0, Gen4 / IMX636 → 3.0); empty if none.
  std::string evt_version() const;

  /// From `% geometry WxH`, `% format ...;width=W;height=H`, `% Width W` +
  /// `% Height H`, else from the camera plugin name; nullopt if unknown.
  std::optional<SensorSize> sensor_size() const;
};

/// Parses the header at the start of `file` and leaves the file positioned
/// after it. Throws ReadError if a header line is unreasonably long.
PropheseeHeader read_prophesee_header(ChunkedFile& file);

/// Parses a header held in memory (for sniffing); nullopt if `head` does not
/// start with '%'; a header longer than `head` gives the lines that fit.
std::optional<PropheseeHeader> parse_prophesee_header(std::span<const std::byte> head);

/// True when `head` starts a Prophesee RAW header of this EVT version ("2.0", ...).
inline bool is_prophesee_raw(std::span<const std::byte> head, std::string_view evt_version) {
  const auto header = parse_prophesee_header(head);
  return header && header->evt_version() == evt_version;
}

}  // namespace evlife::io
