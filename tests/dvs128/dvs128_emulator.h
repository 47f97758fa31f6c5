// An emulated DVS128 for tests: umockdev's in-process usbdevfs emulation, so
// that the REAL libusb code path (enumeration, open, claim, control and bulk
// URBs, cancel, unplug) runs unmodified. The test binary must run under
// `umockdev-wrapper` (LD_PRELOAD of libumockdev-preload); tests/CMake does it.
//
// The emulator answers the usbdevfs ioctls libusb issues: it records every
// control request (setup + data) the "camera" received, answers string
// descriptor requests (serial number), completes bulk-IN URBs on 0x86 with
// the packets the test pushed, one packet per URB, and can vanish (unplug).
// The ioctl handler runs on umockdev's own thread: all state is locked.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace evlife::testing {

struct ControlRequest {
  std::uint8_t request_type = 0;
  std::uint8_t request = 0;
  std::uint16_t value = 0;
  std::uint16_t index = 0;
  std::vector<std::uint8_t> data;  ///< OUT data stage
};

class EmulatedDvs128;

/// Owns the umockdev testbed; add devices before creating any libusb context.
class UsbTestbed {
 public:
  UsbTestbed();
  ~UsbTestbed();
  UsbTestbed(const UsbTestbed&) = delete;
  UsbTestbed& operator=(const UsbTestbed&) = delete;

  /// A DVS128 at /dev/bus/usb/<bus>/<address> with the given serial number.
  EmulatedDvs128& add_dvs128(std::string serial = "DVS128-0042", int firmware_version = 14,
                             int bus = 1, int address = 2);
  /// Some other USB device (shows up in enumeration, is not a camera).
  void add_other_device(std::uint16_t vendor_id, std::uint16_t product_id, int bus, int address);

 private:
  void add_description(std::uint16_t vid, std::uint16_t pid, int bcd_device, int bus, int address,
                       const std::string& descriptor_hex);
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::vector<std::unique_ptr<EmulatedDvs128>> cameras_;
};

class EmulatedDvs128 {
 public:
  EmulatedDvs128(std::string serial, std::string devnode);
  ~EmulatedDvs128();
  EmulatedDvs128(const EmulatedDvs128&) = delete;
  EmulatedDvs128& operator=(const EmulatedDvs128&) = delete;

  /// Queues one bulk packet on 0x86 (completes one URB, may be any size up to
  /// the URB's buffer; larger packets are split across URBs).
  void push_packet(std::vector<std::uint8_t> bytes);
  /// Packets not yet handed to a URB.
  std::size_t queued_packets() const;
  /// Bulk URBs on 0x86 waiting for data.
  int waiting_urbs() const;
  /// The camera vanishes: packets already pushed are still delivered, then
  /// every pending URB completes with -ESHUTDOWN and later ioctls fail ENODEV.
  void unplug();
  /// Another program holds the camera: CLAIMINTERFACE fails with EBUSY.
  void set_busy(bool busy);
  /// A camera that does not answer: its string descriptors (the serial
  /// number) stall.
  void set_strings_stall(bool stall);
  /// The next bulk packet's URB completes with -errno_value instead (a
  /// transfer error, e.g. EPROTO); the packet's data is lost.
  void fail_next_packet(int errno_value);

  std::vector<ControlRequest> control_requests() const;
  /// Just the bRequest of each vendor request (bmRequestType 0x40), in order.
  std::vector<std::uint8_t> vendor_requests() const;
  int claims() const;
  int releases() const;
  /// Bulk URBs completed with data / discarded (cancelled) so far.
  int urbs_completed() const;
  int urbs_discarded() const;

  /// Waits (polling, bounded) until pred() holds under the emulator's lock.
  bool wait_for(const std::function<bool()>& pred,
                std::chrono::milliseconds timeout = std::chrono::milliseconds(2000)) const;

  // Called by the ioctl handler (umockdev's thread).
  struct Impl;
  Impl& impl() { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

/// Little-endian event words, for building packets.
std::vector<std::uint8_t> words_to_bytes(const std::vector<std::uint32_t>& words);
/// An event word from raw fields (raw = as on the wire, before axis flips).
std::uint32_t dvs128_word(int raw_x, int raw_y, bool raw_polarity_bit, int ts14_us);
inline constexpr std::uint32_t kWrapWord = 0x80000000u;
inline constexpr std::uint32_t kResetWord = 0x40000000u;
inline constexpr std::uint32_t kSyncWordFlag = 0x00008000u;

}  // namespace evlife::testing
