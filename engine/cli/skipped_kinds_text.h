// The skipped records of a reader split by kind, for the summaries of
// `evlife info`, `process` and `convert`: "aps-sample 1200, imu-word 14";
// empty when the format does not tell its skipped records apart.
#pragma once

#include <string>

#include "evlife/io/event_reader.h"

namespace evlife::cli {

std::string skipped_kinds_text(const io::EventReader& reader);

}  // namespace evlife::cli
