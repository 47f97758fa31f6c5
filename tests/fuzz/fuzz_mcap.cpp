// libFuzzer target: the MCAP reader (magic, Header, Footer and summary,
// records, none/zstd/lz4 chunks of one or several frames, the chunk,
// data-section and summary CRCs, CDR message decoding),
// through open_event_reader (extension .mcap). See fuzz_event_reader.h for
// what counts as a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz_event_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return evlife::fuzz::fuzz_event_reader(data, size, ".mcap");
}
