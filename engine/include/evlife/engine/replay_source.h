// A recording replayed through the EventSource interface: from a file (via
// io's streaming reader, constant memory) or from events already in memory
// (tests, benches, embedding). As fast as possible, or paced by the event
// clock at `speed` x real time (--realtime[=K]).
#pragma once

#include <atomic>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "evlife/engine/event_clock_pacer.h"
#include "evlife/engine/event_source.h"
#include "evlife/engine/notice_ring.h"
#include "evlife/io/event_reader.h"

namespace evlife::engine {

class ReplaySource final : public EventSource {
 public:
  /// Packet period of paced replays unless set: a tenth of a millisecond,
  /// short against the lifetimes (milliseconds) yet a few dozen events per
  /// packet at camera rates, so the engine's per-packet costs stay small.
  static constexpr std::int64_t kDefaultPacketUs = 100;

  /// Opens `path` (format sniffed by io) with bounds and time-order checks.
  /// Sensor: the format's where it states one, else `sensor`, else a scan of
  /// the data. Throws io::ReadError if the file cannot be opened.
  /// `input`: the input selection (topic...; its sensor is replaced).
  /// `stop`, when set during the scan, ends it early (the caller checks it).
  static std::unique_ptr<ReplaySource> open_file(const std::string& path,
                                                 std::optional<SensorSize> sensor,
                                                 double speed = 0.0,
                                                 const io::ReaderOptions& input = {},
                                                 const std::atomic<bool>* stop = nullptr);

  /// Replays any io reader (e.g. io::SyntheticSceneReader: a camera-free
  /// live source when kind == live). Throws std::invalid_argument without a
  /// sensor size.
  static std::unique_ptr<ReplaySource> from_reader(std::unique_ptr<io::EventReader> reader,
                                                   std::optional<SensorSize> sensor,
                                                   double speed = 0.0,
                                                   SourceKind kind = SourceKind::offline);

  /// Replays `events` in memory (viewed, not copied: they must outlive the source).
  ReplaySource(std::span<const Event> events, SensorSize sensor, double speed = 0.0,
               SourceKind kind = SourceKind::offline);

  std::size_t pull(std::span<Event> out) noexcept override;
  SourceStatus status() const noexcept override { return status_; }
  std::string error_message() const override { return error_; }
  SensorSize sensor_size() const noexcept override { return sensor_; }
  SourceKind kind() const noexcept override { return kind_; }
  std::string describe() const override { return description_; }
  /// For readers that are not files (a generated scene): what the run's
  /// summary calls the source instead of "file:PATH (format)".
  void describe_as(std::string description) { description_ = std::move(description); }
  void request_stop() noexcept override { stop_.store(true, std::memory_order_relaxed); }
  std::int64_t last_arrival_ns() const noexcept override { return last_arrival_ns_; }
  std::int64_t last_oldest_ns() const noexcept override { return last_oldest_ns_; }
  double fraction_read() const noexcept override { return fraction_read_.load(std::memory_order_relaxed); }
  /// Paced: each stretch without events of kEventGapNoticeUs or more, said
  /// before the replay waits it out (a timestamp outlier would have it wait
  /// hours in silence).
  std::string take_notice() override;

  /// Paced replays hand events over in packets, as a camera's USB transfers
  /// do: every `packet_us` of wall-clock time, the events due by then (an
  /// event's arrival is the end of its packet). 0: whatever is due whenever
  /// the engine asks (arrival = when the first of them was due). Set before
  /// the first pull().
  void set_packet_us(std::int64_t packet_us) noexcept { packet_ns_ = packet_us * 1000; }

  /// The reader replayed (its skipped-record counts for the summary); null
  /// for a memory replay. Not to be read while the engine runs.
  const io::EventReader* reader() const noexcept { return reader_.get(); }

 private:
  ReplaySource(std::unique_ptr<io::EventReader> reader, SensorSize sensor, double speed,
               SourceKind kind);
  bool refill() noexcept;  // false: nothing more (status set)

  std::unique_ptr<io::EventReader> reader_;  // null: memory replay
  std::span<const Event> memory_;
  std::vector<Event> buffer_;  // file read-ahead
  std::span<const Event> pending_;  // read, not yet handed out
  SensorSize sensor_;
  SourceKind kind_ = SourceKind::offline;
  EventClockPacer pacer_;
  std::string description_;
  SourceStatus status_ = SourceStatus::ok;
  std::string error_;
  std::int64_t last_arrival_ns_ = 0;
  std::int64_t last_oldest_ns_ = 0;
  std::int64_t packet_ns_ = kDefaultPacketUs * 1000;
  std::atomic<bool> stop_{false};
  std::uint64_t file_bytes_ = 0;  // 0: unknown (not a regular file)
  // --to: the share read is the share of the selected span's time passed
  // (the bytes after its end are never read), from its first event on.
  std::int64_t crop_span_us_ = 0;  // 0: no --to
  std::int64_t crop_first_t_us_ = INT64_MIN;
  std::atomic<double> fraction_read_{-1.0};
  // Paced: the last event handed out (INT64_MIN: none yet) and the long
  // waits to say, each as (that event's time, the next event's).
  std::int64_t released_t_us_ = INT64_MIN;
  struct Wait {
    std::int64_t from_us = 0;
    std::int64_t next_us = 0;
  };
  NoticeRing<Wait, 4> waits_;
};

}  // namespace evlife::engine
