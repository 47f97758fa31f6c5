#include "cropping_event_reader.h"

namespace evlife::io::detail {

CroppingEventReader::CroppingEventReader(std::unique_ptr<EventReader> inner, const ReaderOptions& options)
    : WrappingEventReader(std::move(inner)), from_us_(options.from_us), to_us_(options.to_us), polarity_(options.polarity) {}

std::size_t CroppingEventReader::read(std::span<Event> out) {
  if (done_ || out.empty()) return 0;
  if (!first_t_ && from_us_) {  // a reader that can seek starts at --from without decoding what precedes it
    first_t_ = inner_->first_event_time_us();
    if (first_t_) inner_->skip_events_before(*first_t_ + *from_us_);
  }
  while (true) {
    const std::size_t n = inner_->read(out);
    if (n == 0) return 0;
    if (!first_t_) first_t_ = out[0].t_us;
    const std::int64_t begin = from_us_ ? *first_t_ + *from_us_ : INT64_MIN;
    const std::int64_t end = to_us_ ? *first_t_ + *to_us_ : INT64_MAX;
    std::size_t kept = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const Event& e = out[i];
      if (e.t_us >= end) {
        done_ = true;
        break;
      }
      if (e.t_us < begin) continue;
      if (polarity_ == PolarityFilter::on && e.p <= 0) continue;
      if (polarity_ == PolarityFilter::off && e.p > 0) continue;
      out[kept++] = e;
    }
    if (kept > 0 || done_) return kept;
  }
}

}  // namespace evlife::io::detail
