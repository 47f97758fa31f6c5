#include "evlife/engine/replay_source.h"

#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <thread>

#include "evlife/engine/monotonic_clock.h"
#include "evlife/engine/prefetch_reader.h"
#include "evlife/io/sensor_size_from_data.h"
#include "evlife/io/stream_copy_name.h"

namespace evlife::engine {
namespace {
constexpr std::size_t kReadAheadEvents = 16384;
// Paced, the reader is read ahead on its own thread; copy from it in small
// pieces so the source thread is never busy long while packets fall due.
constexpr std::size_t kPacedReadAheadEvents = 1024;
constexpr std::int64_t kMaxSleepNs = 1'000'000;  // stay responsive to request_stop()
// A sleep ends late (on the README's VM ~30 us median, 60-90 us p99, even with
// 1 ns timer slack); a camera's packet does not. Sleep until this long
// before a packet is due (at most half a packet period), then poll the clock
// yielding the core, so that the replay delivers on time instead of charging
// its own wake-up to the engine.
constexpr std::int64_t kMaxPollNs = 60'000;
}  // namespace

std::unique_ptr<ReplaySource> ReplaySource::open_file(const std::string& path,
                                                      std::optional<SensorSize> sensor,
                                                      double speed,
                                                      const io::ReaderOptions& input,
                                                      const std::atomic<bool>* stop) {
  // The format's size, else the user's, else one scan of the data; then a
  // checked reader (bounds, time order) so bad data stops with its index.
  const io::ResolvedSensorSize size = io::resolve_sensor_size(path, sensor, input, stop);
  io::ReaderOptions checked = input;
  checked.sensor = size.size;
  checked.require_time_order = true;
  auto source = from_reader(io::open_event_reader(path, checked), size.size, speed, SourceKind::offline);
  if (input.to_us) source->crop_span_us_ = std::max<std::int64_t>(1, *input.to_us - input.from_us.value_or(0));
  return source;
}

std::unique_ptr<ReplaySource> ReplaySource::from_reader(std::unique_ptr<io::EventReader> reader,
                                                        std::optional<SensorSize> sensor,
                                                        double speed, SourceKind kind) {
  const std::optional<SensorSize> size = sensor ? sensor : reader->sensor_size();
  if (!size)
    throw std::invalid_argument(io::name_in_messages(reader->path()) +
                                ": the file does not state its sensor size; give --sensor WxH");
  return std::unique_ptr<ReplaySource>(new ReplaySource(std::move(reader), *size, speed, kind));
}

namespace {
// Paced, decoding must not stall the source thread: read ahead on a thread.
std::unique_ptr<io::EventReader> read_ahead_if_paced(std::unique_ptr<io::EventReader> reader,
                                                     double speed) {
  if (speed <= 0.0) return reader;
  return std::make_unique<PrefetchReader>(std::move(reader));
}
}  // namespace

ReplaySource::ReplaySource(std::unique_ptr<io::EventReader> reader, SensorSize sensor,
                           double speed, SourceKind kind)
    : reader_(read_ahead_if_paced(std::move(reader), speed)), buffer_(kReadAheadEvents), sensor_(sensor), kind_(kind),
      pacer_(speed),
      description_("file:" + io::name_in_messages(reader_->path()) + " (" + std::string(reader_->format_name()) + ")") {
  std::error_code ec;
  if (std::filesystem::is_regular_file(reader_->path(), ec)) file_bytes_ = std::filesystem::file_size(reader_->path(), ec);
  if (ec) file_bytes_ = 0;
}

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
    const std::size_t want = pacer_.paced() ? kPacedReadAheadEvents : buffer_.size();
    const std::size_t n = reader_->read(std::span<Event>(buffer_.data(), want));
    if (n == 0) {
      if (crop_span_us_ > 0) fraction_read_.store(1.0, std::memory_order_relaxed);  // the span's end
      status_ = SourceStatus::end_of_stream;
      return false;
    }
    pending_ = std::span<const Event>(buffer_.data(), n);
    if (crop_span_us_ > 0) {
      if (crop_first_t_us_ == INT64_MIN) crop_first_t_us_ = buffer_[0].t_us;
      const auto passed = static_cast<double>(buffer_[n - 1].t_us - crop_first_t_us_);
      fraction_read_.store(std::min(1.0, passed / static_cast<double>(crop_span_us_)), std::memory_order_relaxed);
    } else if (const std::uint64_t read = reader_->bytes_consumed(); file_bytes_ > 0 && read > 0) {
      fraction_read_.store(std::min(1.0, static_cast<double>(read) / static_cast<double>(file_bytes_)),
                           std::memory_order_relaxed);
    }
    return true;
  } catch (const std::exception& e) {
    error_ = e.what();
  } catch (...) {
    error_ = io::name_in_messages(reader_->path()) + ": unknown read error";
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
  if (out.empty() || !refill()) return 0;
  std::size_t n = std::min(out.size(), pending_.size());
  const std::int64_t now_ns = monotonic_ns();
  const std::int64_t due_us = pacer_.due_until_us(pending_.front().t_us, now_ns);
  if (pacer_.paced()) {
    const std::int64_t next_t_us = pending_.front().t_us;
    std::int64_t gap_us = 0;  // times up to 2^62 apart each way: overflowed, the gap is huge (time order)
    if (released_t_us_ != INT64_MIN &&
        (__builtin_sub_overflow(next_t_us, released_t_us_, &gap_us) || gap_us >= kEventGapNoticeUs)) {
      waits_.put(Wait{released_t_us_, next_t_us});  // said once: the event is released before the next pull
      released_t_us_ = INT64_MIN;
    }
    // The packet holding the first pending event arrives at the end of its
    // slot; without packets, when the event is due.
    const std::int64_t first_due_ns = pacer_.due_at_ns(pending_.front().t_us);
    const std::int64_t arrival_ns = packet_ns_ > 0 ? pacer_.packet_arrival_ns(first_due_ns, packet_ns_) : first_due_ns;
    if (arrival_ns > now_ns) {  // not arrived yet: sleep towards it
      const std::int64_t wait_ns = arrival_ns - now_ns;
      const std::int64_t poll_ns = std::min(kMaxPollNs, packet_ns_ / 2);
      if (wait_ns > poll_ns) {
        std::this_thread::sleep_for(std::chrono::nanoseconds(std::min(wait_ns - poll_ns, kMaxSleepNs)));
        return 0;
      }
      while (monotonic_ns() < arrival_ns) std::this_thread::yield();  // others may run
    }
    // Events are time-ordered: release the prefix that is due by the
    // arrival (one packet at a time, so a late engine sees each packet's own
    // arrival time), at least the first event (clock rounding).
    const std::int64_t cutoff_us = packet_ns_ > 0 ? pacer_.due_until_us(0, arrival_ns) : due_us;
    const auto first = pending_.begin();
    const auto end = std::upper_bound(first + 1, first + static_cast<std::ptrdiff_t>(n), cutoff_us,
                                      [](std::int64_t t, const Event& e) { return t < e.t_us; });
    n = static_cast<std::size_t>(end - first);
    last_arrival_ns_ = arrival_ns;
    last_oldest_ns_ = first_due_ns;
  }
  released_t_us_ = pending_[n - 1].t_us;
  std::copy_n(pending_.begin(), n, out.begin());
  pending_ = pending_.subspan(n);
  return n;
}

std::string ReplaySource::take_notice() {
  return waits_.take_text(
      [this](const Wait& wait) {
        const double gap_s = (static_cast<double>(wait.next_us) - static_cast<double>(wait.from_us)) * 1e-6;
        const double wait_s = gap_s / pacer_.speed();
        char text[400];
        std::snprintf(text, sizeof text,
                      "warning: the replay waits %.*f s (%.0f s of recording time x 1/%g) for the next event at t = "
                      "%lld us (none since t = %lld us): a gap in the recording; Ctrl-C stops, without --realtime it "
                      "replays at full speed",
                      wait_s < 10.0 ? 2 : 0, wait_s, gap_s, pacer_.speed(), static_cast<long long>(wait.next_us),
                      static_cast<long long>(wait.from_us));
        return std::string(text);
      },
      "waits for the next event");
}

}  // namespace evlife::engine
