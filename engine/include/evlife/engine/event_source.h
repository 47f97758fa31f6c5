// The interface every event source implements: file replay, the DVS128 USB
// camera, a synthetic scene. The engine's source thread drives it by calling
// pull() in a loop and pushes what it returns into the pipeline; the source
// never decides what to drop, and queues only what its device or file hands
// over ahead (a paced replay reads ahead on a thread of its own, as a camera's
// USB transfers arrive while the engine works: see PrefetchReader).
//
// Contract (each point is what the engine relies on):
//  - pull() is called from ONE thread (the engine's source thread, or a
//    test's own thread). It fills `out` with up to out.size() events in
//    non-decreasing time order and returns how many. It may wait, but only
//    briefly (at most ~20 ms, e.g. one USB transfer timeout or one pacing
//    sleep), so that the engine can see a stop request; returning 0 with
//    status() == SourceStatus::ok means "nothing yet, call again".
//  - End of the stream: pull() returns 0 and status() becomes end_of_stream
//    (a file was read to its end) or error (corrupt data, a vanished device,
//    a USB failure). Events decoded before a fault are returned first; the
//    error is reported on the following call, never instead of them. After
//    that, pull() keeps returning 0. The engine ends the run cleanly —
//    everything accepted is processed and written — and the run's exit
//    status is non-zero on error, with error_message() shown.
//  - pull() does not throw: an exception is turned into status() == error by
//    the source (the engine also catches, as a last resort, and treats an
//    escaping exception as an error of the source).
//  - Backpressure and drops are the ENGINE's policy (block for offline
//    sources, drop and count for live ones). A source only counts what it
//    lost itself before the engine saw it (a device FIFO overflow, a lost USB
//    transfer) in lost_events(), so the engine can report it per stage.
//  - request_stop() may be called from any thread (signal handling, the
//    engine's shutdown); it makes a waiting pull() return soon. It must be
//    thread-safe; nothing else is.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "evlife/algo/event.h"

namespace evlife::engine {

enum class SourceStatus {
  ok,             ///< streaming; pull() may return events or 0 (= not yet)
  end_of_stream,  ///< finished normally (file end, stop requested)
  error,          ///< finished on a fault; see error_message()
};

/// How the engine should treat a source unless configured otherwise.
enum class SourceKind {
  offline,  ///< a recording: default policy blocks the source when workers lag
  live,     ///< a camera: default policy drops (counted) rather than block it
};

class EventSource {
 public:
  virtual ~EventSource() = default;

  /// Fills `out` with up to out.size() events, in non-decreasing time order;
  /// returns how many (0 = none now, or finished: check status()). Never throws.
  virtual std::size_t pull(std::span<Event> out) noexcept = 0;

  /// ok while streaming, then end_of_stream or error (final).
  virtual SourceStatus status() const noexcept = 0;

  /// Human-readable cause when status() == error, naming the file or device
  /// and the byte offset / event index where known. Empty otherwise.
  virtual std::string error_message() const = 0;

  /// Sensor geometry. Known at construction (from the file, the device, or
  /// the user's --sensor); the engine sizes its state from it.
  virtual SensorSize sensor_size() const noexcept = 0;

  virtual SourceKind kind() const noexcept = 0;

  /// What this is, for logs: "file:/path/x.mat", "usb:DVS128 serial 0042".
  virtual std::string describe() const = 0;

  /// Events the source lost before handing them over (device overflow, lost
  /// transfers, events outside the sensor it refused). 0 for files.
  virtual std::uint64_t lost_events() const noexcept { return 0; }
  /// Reads from the device that failed (a USB transfer ending in an error):
  /// the events they held are lost, and when the failure reports no data,
  /// lost_events() cannot count them; the summary shows both. 0 for files.
  virtual std::uint64_t failed_transfers() const noexcept { return 0; }

  /// When the events of the last pull() arrived, steady-clock ns (the
  /// engine's latency starts there); 0 = "now" (the engine stamps the chunk
  /// when pull() returns). A camera returns when the USB transfer holding
  /// them completed; a paced replay, when the packet holding them was due,
  /// so a lagging engine shows as latency, not as a slower clock.
  virtual std::int64_t last_arrival_ns() const noexcept { return 0; }

  /// When the oldest event of the last pull() happened, steady-clock ns, if
  /// the source knows (a paced replay: when it was due); 0 = unknown. The
  /// engine reports its age at output beside the latency: the latency plus
  /// the time the event waited for its packet.
  virtual std::int64_t last_oldest_ns() const noexcept { return 0; }

  /// Share of a finite input read so far (0..1), for the progress line; any
  /// thread. Negative when unknown (live sources, inputs of unknown size).
  virtual double fraction_read() const noexcept { return -1.0; }

  /// The next warning for the user, oldest first, taken by the engine's
  /// monitor thread (pull() does not print) until it is empty: none (yet).
  virtual std::string take_notice() { return {}; }

  /// Asks a pull() in progress (or the next one) to return promptly and the
  /// source to finish with end_of_stream. Thread-safe; idempotent.
  virtual void request_stop() noexcept = 0;

 protected:
  EventSource() = default;
  EventSource(const EventSource&) = default;
  EventSource& operator=(const EventSource&) = default;
};

}  // namespace evlife::engine
