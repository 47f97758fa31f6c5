// Private: applies ReaderOptions' cropping (--from/--to, relative to the
// first event of the file) and polarity filter to any reader. Errors of the
// inner reader pass through after the kept events before them. Where the
// inner reader can seek (HDF5), --from starts there by a search on t: the
// events before it are not decoded (nor checked: the file must be in time
// order, as evlife and the datasets write it).
#pragma once

#include <memory>

#include "wrapping_event_reader.h"

namespace evlife::io::detail {

class CroppingEventReader final : public WrappingEventReader {
 public:
  CroppingEventReader(std::unique_ptr<EventReader> inner, const ReaderOptions& options);

  std::size_t read(std::span<Event> out) override;

 private:
  std::optional<std::int64_t> from_us_;
  std::optional<std::int64_t> to_us_;
  PolarityFilter polarity_;
  std::optional<std::int64_t> first_t_;
  bool done_ = false;
};

}  // namespace evlife::io::detail
