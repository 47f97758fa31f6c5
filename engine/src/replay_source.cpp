#include "evlife/engine/replay_source.h"

#include <algorithm>
#include <exception>
#include <stdexcept>
#include <thread>

#include "evlife/engine/monotonic_clock.h"
#include "evlife/io/sensor_size_from_data.h"

namespace evlife::engine {
namespace {
constexpr std::size_t kReadAheadEvents = 16384;
constexpr std::int64_t kMaxSleepNs = 1'000'000;  // stay responsive to request_stop()
}  // namespace

std::unique_ptr<ReplaySource> ReplaySource::open_file(const std::string& path,
                                                      std::optional<SensorSize> sensor,
                                                      double speed) {
  // The format's size, else the user's, else one scan of the data; then a
  // checked reader (bounds, time order) so bad data stops with its index.
  const io::ResolvedSensorSize size = io::resolve_sensor_size(path, sensor);
  return from_reader(io::open_event_reader(path, io::ReaderOptions{size.size, true}), size.size,
                     speed, SourceKind::offline);
}

std::unique_ptr<ReplaySource> ReplaySource::from_reader(std::unique_ptr<io::EventReader> reader,
                                                        std::optional<SensorSize> sensor,
                                                        double speed, SourceKind kind) {
  const std::optional<SensorSize> size = sensor ? sensor : reader->sensor_size();
  if (!size)
    throw std::invalid_argument(reader->path() +
                                ": the file does not state its sensor size; give --sensor WxH");
  return std::unique_ptr<ReplaySource>(new ReplaySource(std::move(reader), *size, speed, kind));
}

ReplaySource::ReplaySource(std::unique_ptr<io::EventReader> reader, SensorSize sensor,
                           double speed, SourceKind kind)
    : reader_(std::move(reader)), buffer_(kReadAheadEvents), sensor_(sensor), kind_(kind),
      pacer_(speed),
      description_("file:" + reader_->path() + " (" + std::string(reader_->format_name()) + ")") {}

ReplaySource::ReplaySource(std::span<const Event> events, SensorSize sensor, double speed,
                           SourceKind kind)
    : memory_(events), pending_(events), sensor_(sensor), kind_(kind), pacer_(speed),
      description_("memory:" + std::to_string(events.size()) + " events") {}

bool ReplaySource::refill() noexcept {
  if (!pending_.empty()) return true;
  if (reader_ == nullptr) {
    status_ = SourceStatus::end_of_stream;
    return false;
  }
  try {
    const std::size_t n = reader_->read(std::span<Event>(buffer_.data(), buffer_.size()));
    if (n == 0) {
      status_ = SourceStatus::end_of_stream;
      return false;
    }
    pending_ = std::span<const Event>(buffer_.data(), n);
    return true;
  } catch (const std::exception& e) {
    error_ = e.what();
  } catch (...) {
    error_ = reader_->path() + ": unknown read error";
  }
  status_ = SourceStatus::error;
  return false;
}

std::size_t ReplaySource::pull(std::span<Event> out) noexcept {
  if (status_ != SourceStatus::ok) return 0;
  if (stop_.load(std::memory_order_relaxed)) {
    status_ = SourceStatus::end_of_stream;
    return 0;
  }
  if (!refill()) return 0;
  std::size_t n = std::min(out.size(), pending_.size());
  const std::int64_t now_ns = monotonic_ns();
  const std::int64_t due_us = pacer_.due_until_us(pending_.front().t_us, now_ns);
  if (pacer_.paced()) {
    if (pending_.front().t_us > due_us) {  // nothing due yet: sleep towards it
      const std::int64_t wait_ns =
          std::min(pacer_.due_at_ns(pending_.front().t_us) - now_ns, kMaxSleepNs);
      if (wait_ns > 0) std::this_thread::sleep_for(std::chrono::nanoseconds(wait_ns));
      return 0;
    }
    // Events are time-ordered: release the prefix that is due.
    const auto end = std::upper_bound(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(n), due_us,
                                      [](std::int64_t t, const Event& e) { return t < e.t_us; });
    n = static_cast<std::size_t>(end - pending_.begin());
    last_arrival_ns_ = pacer_.due_at_ns(pending_.front().t_us);
  }
  std::copy_n(pending_.begin(), n, out.begin());
  pending_ = pending_.subspan(n);
  return n;
}

}  // namespace evlife::engine
