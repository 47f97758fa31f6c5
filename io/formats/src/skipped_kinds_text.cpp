#include "evlife/io/event_reader.h"

namespace evlife::io {

std::string skipped_kinds_text(const EventReader& reader) { return skipped_kinds_text(reader.skipped_record_kinds()); }

std::string skipped_kinds_text(const std::vector<SkippedKindCount>& kinds) {
  std::string text;
  for (const SkippedKindCount& k : kinds) {
    if (!text.empty()) text += ", ";
    text.append(k.kind);
    text += ' ' + std::to_string(k.count);
  }
  return text;
}

std::string skipped_records_note(const EventReader& reader) {
  const std::string kinds = skipped_kinds_text(reader);
  return "(non-event records of the format" + (kinds.empty() ? "" : ": " + kinds) + ")";
}

std::string skipped_records_text(const EventReader& reader) {
  return std::to_string(reader.skipped_record_count()) + " " + skipped_records_note(reader);
}

}  // namespace evlife::io
