#include "skipped_kinds_text.h"

namespace evlife::cli {

std::string skipped_kinds_text(const io::EventReader& reader) {
  std::string text;
  for (const io::SkippedKindCount& k : reader.skipped_record_kinds()) {
    if (!text.empty()) text += ", ";
    text.append(k.kind);
    text += ' ' + std::to_string(k.count);
  }
  return text;
}

}  // namespace evlife::cli
