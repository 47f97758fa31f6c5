// The DVS128 camera as an engine source (SourceKind::live). pull() runs on
// the engine's source thread and is the camera's reader loop: it decodes the
// completed bulk transfers straight into the engine's buffer, resubmits them,
// and otherwise runs one short step of libusb's event loop. It never blocks
// longer than `wait` and never drops anything itself: overload is the
// engine's policy (drop and count, for live sources).
//
// Axes as every file reader: x = 0 left, y = 0 top (x = 127 - raw x,
// y = 127 - raw y), polarity raw bit 0 = 0 -> ON; see io/dvs128_decoder.h.
//
// For `evlife run`: make_dvs128_source("dvs128[:SERIAL]", biases), the
// --biases file read while its command line is parsed.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "evlife/engine/event_source.h"
#include "evlife/io/dvs128_biases.h"
#include "evlife/io/dvs128_decoder.h"
#include "evlife/io/dvs128_device.h"

namespace evlife::engine {

class Dvs128Source final : public EventSource {
 public:
  struct Options {
    std::string serial;  ///< empty: the first DVS128 found
    io::Dvs128Biases biases;
    int transfer_count = 8;
    int transfer_bytes = 4096;
    /// Longest a pull() waits in libusb's event loop when no data is ready.
    std::chrono::microseconds wait{std::chrono::milliseconds(10)};
    /// Optional timing probe (latency measurements, embedding): called on
    /// the source thread when decoding of a bulk transfer begins, with the
    /// steady-clock time (ns) its completion callback ran. Must be cheap.
    void (*on_transfer)(void* user, std::int64_t completed_ns) = nullptr;
    void* on_transfer_user = nullptr;
  };

  /// Opens, configures and biases the camera (streaming starts at the first
  /// pull()). Throws io::Dvs128Error with a message naming the device and
  /// what to check (not found, permissions / udev rule, busy, firmware).
  explicit Dvs128Source(const Options& options);
  ~Dvs128Source() override;

  std::size_t pull(std::span<Event> out) noexcept override;
  SourceStatus status() const noexcept override {
    return status_.load(std::memory_order_acquire);
  }
  std::string error_message() const override { return error_; }
  SensorSize sensor_size() const noexcept override { return {128, 128}; }
  SourceKind kind() const noexcept override { return SourceKind::live; }
  std::string describe() const override;
  void request_stop() noexcept override { stop_.store(true, std::memory_order_relaxed); }
  /// Words (events, upper bound) that arrived in failed bulk transfers.
  /// Failed transfers that report no data cannot be counted in events: see
  /// device().transfers_failed().
  std::uint64_t lost_events() const noexcept override { return device_->bytes_lost() / 4; }
  std::uint64_t failed_transfers() const noexcept override { return device_->transfers_failed(); }

  /// Decoder counters (sync events, wraps, resets...). Source thread only.
  const io::Dvs128DecoderCounters& decoder_counters() const noexcept {
    return decoder_.counters();
  }
  const io::Dvs128Device& device() const noexcept { return *device_; }

 private:
  std::size_t drain(std::span<Event> out) noexcept;
  void finish(SourceStatus status, std::string message) noexcept;

  std::unique_ptr<io::Dvs128Device> device_;
  io::Dvs128Decoder decoder_;
  std::size_t chunk_offset_ = 0;  ///< bytes of the front chunk already decoded
  std::chrono::microseconds wait_;
  void (*on_transfer_)(void*, std::int64_t) = nullptr;
  void* on_transfer_user_ = nullptr;
  bool started_ = false;
  std::atomic<bool> stop_{false};
  std::atomic<SourceStatus> status_{SourceStatus::ok};
  std::string error_;
};

/// True for "dvs128" and "dvs128:SERIAL" (the --source spec of a camera).
bool is_dvs128_spec(std::string_view spec);

/// Creates the camera source from "dvs128[:SERIAL]"; `biases_file` (may be
/// empty = defaults) is read with io::Dvs128Biases::load_file. Throws
/// io::Dvs128Error / std::runtime_error with a message ready for the user.
std::unique_ptr<Dvs128Source> make_dvs128_source(std::string_view spec,
                                                 const std::string& biases_file = {});
/// The same with the biases given (read by the caller: `evlife run` reads
/// its --biases file while parsing, where a bad one is a setting refused).
std::unique_ptr<Dvs128Source> make_dvs128_source(std::string_view spec, const io::Dvs128Biases& biases);

}  // namespace evlife::engine
