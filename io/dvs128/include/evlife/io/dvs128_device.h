// The DVS128 camera over libusb: find, open, configure, claim, send biases,
// reset timestamps, start, keep asynchronous bulk transfers in flight on
// endpoint 0x86, stop. It owns no thread: whoever drives it (the engine's
// source thread) calls handle_events() in a loop, and every libusb call and
// transfer callback then happens on that one thread. Completed transfers wait
// in completion order until released; release_front() resubmits them.
// Nothing here decodes, logs or allocates per transfer.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "evlife/io/dvs128_biases.h"

struct libusb_context;
struct libusb_device_handle;
struct libusb_transfer;

namespace evlife::io {

/// A device-boundary failure (not found, permission, busy, firmware too old,
/// control transfer failed). The message names the device and what to check.
class Dvs128Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct UsbDeviceSummary {
  int bus = 0;
  int address = 0;
  std::uint16_t vendor_id = 0;
  std::uint16_t product_id = 0;
};

struct Dvs128DeviceInfo {
  int bus = 0;
  int address = 0;
  int firmware_version = 0;  ///< low byte of bcdDevice
  std::string serial;        ///< empty when the device could not be opened
  std::string problem;       ///< why it could not be opened (permissions...), else empty
  std::string describe() const;  ///< "DVS128 serial 0042 (bus 1 device 2, firmware 14)"
};

/// Every USB device libusb sees (for the "no camera" diagnostics). Throws Dvs128Error.
std::vector<UsbDeviceSummary> list_usb_devices();
/// Every attached DVS128; each is opened briefly to read its serial number.
/// Throws Dvs128Error only when libusb itself cannot start.
std::vector<Dvs128DeviceInfo> list_dvs128_devices();
/// The checklist shown when no camera is usable (cable, permissions, udev rule).
std::string dvs128_troubleshooting();

struct Dvs128DeviceOptions {
  std::string serial;  ///< empty: the first DVS128 found
  Dvs128Biases biases;
  int transfer_count = 8;     ///< asynchronous bulk transfers kept in flight
  int transfer_bytes = 4096;  ///< bytes per transfer (multiple of 512)
};

enum class Dvs128State {
  opened,     ///< configured and biased, not streaming yet
  streaming,  ///< start() done, transfers in flight
  stopped,    ///< stop() done (or never started)
  vanished,   ///< the device disappeared (unplugged) while streaming
  failed,     ///< a transfer or USB error ended streaming; see error_message()
};

class Dvs128Device {
 public:
  /// Finds (by serial when given), opens, sets configuration 1, claims
  /// interface 0, checks the firmware and sends the biases. Throws Dvs128Error.
  explicit Dvs128Device(const Dvs128DeviceOptions& options);
  ~Dvs128Device();  ///< stop(), frees every transfer, closes
  Dvs128Device(const Dvs128Device&) = delete;
  Dvs128Device& operator=(const Dvs128Device&) = delete;

  const Dvs128DeviceInfo& info() const noexcept { return info_; }

  /// Resets the timestamps (0xBB), starts the event transfer (0xB3) and
  /// submits every bulk transfer. Throws Dvs128Error when a request fails or
  /// no transfer could be submitted; if the camera vanishes after some were,
  /// state() says so once they are reaped (their data stays readable).
  void start();

  /// One step of libusb's event loop, waiting at most `timeout` (0 = poll).
  /// Transfer callbacks run inside it. Never throws.
  void handle_events(std::chrono::microseconds timeout) noexcept;

  /// A completed transfer's payload and when its callback ran (steady clock).
  struct Chunk {
    std::span<const std::uint8_t> bytes;
    std::int64_t completed_ns = 0;
  };
  bool has_data() const noexcept { return ready_count_ > 0; }
  /// Oldest completed, unreleased transfer; empty bytes when none.
  Chunk front() const noexcept;
  /// Done with front(): resubmits that transfer while streaming.
  void release_front() noexcept;

  /// Cancels and reaps every transfer (bounded wait), sends STOP (0xB4)
  /// unless the device vanished, releases the interface. Data already
  /// completed stays readable through front(). Idempotent, never throws.
  void stop() noexcept;

  Dvs128State state() const noexcept { return state_.load(std::memory_order_acquire); }
  int transfers_in_flight() const noexcept { return in_flight_; }
  /// Why streaming ended when state() is vanished or failed.
  const std::string& error_message() const noexcept { return error_; }

  std::uint64_t bytes_received() const noexcept { return bytes_received_; }
  std::uint64_t transfers_completed() const noexcept { return transfers_completed_; }
  /// Transfers that completed with an error: their data, if any, is lost.
  /// (Atomic, as bytes_lost(): the engine's monitor reads them mid-run.)
  std::uint64_t transfers_failed() const noexcept { return transfers_failed_.load(std::memory_order_relaxed); }
  /// Bytes the failed transfers reported having received (lost with them).
  std::uint64_t bytes_lost() const noexcept { return bytes_lost_.load(std::memory_order_relaxed); }

 private:
  struct Slot {
    Dvs128Device* device = nullptr;
    libusb_transfer* transfer = nullptr;
    std::unique_ptr<std::uint8_t[]> buffer;
    bool in_flight = false;
    std::int64_t completed_ns = 0;
  };
  static void on_transfer(libusb_transfer* transfer);
  void handle_completion(Slot& slot) noexcept;
  bool submit(Slot& slot) noexcept;
  void push_ready(Slot& slot) noexcept;
  void fail(Dvs128State state, std::string message) noexcept;
  void vendor_request(std::uint8_t request, std::span<const std::uint8_t> data,
                      const char* what);
  void close() noexcept;

  libusb_context* ctx_ = nullptr;
  libusb_device_handle* handle_ = nullptr;
  bool interface_claimed_ = false;
  Dvs128DeviceInfo info_;
  Dvs128Biases biases_;
  int transfer_bytes_ = 0;
  std::vector<Slot> slots_;
  std::vector<int> ready_;  ///< ring of completed slot indices, capacity = slot count
  int ready_head_ = 0;
  int ready_count_ = 0;
  int in_flight_ = 0;
  std::atomic<Dvs128State> state_{Dvs128State::opened};
  bool started_ = false;  ///< START sent and STOP not yet
  std::string error_;
  std::uint64_t bytes_received_ = 0;
  std::uint64_t transfers_completed_ = 0;
  std::atomic<std::uint64_t> transfers_failed_{0};  // written on the thread handling events only
  std::atomic<std::uint64_t> bytes_lost_{0};
};

}  // namespace evlife::io
