#include "evlife/io/dvs128_device.h"

#include <libusb.h>

#include <algorithm>
#include <cstdio>
#include <utility>

#include "evlife/io/dvs128_protocol.h"

namespace evlife::io {

namespace {

constexpr unsigned kControlTimeout_ms = 1000;
constexpr auto kStopReapBudget = std::chrono::milliseconds(1000);

std::string usb_error(int code) { return libusb_error_name(code); }

std::string hex4(std::uint16_t v) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%04x", v);
  return buf;
}

std::string device_node(int bus, int address) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "/dev/bus/usb/%03d/%03d", bus, address);
  return buf;
}

std::int64_t steady_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// RAII for a libusb context and a device list: the enumeration helpers throw.
struct Context {
  libusb_context* ctx = nullptr;
  Context() {
    if (const int r = libusb_init(&ctx); r != 0) {
      ctx = nullptr;
      throw Dvs128Error("cannot start libusb (" + usb_error(r) +
                        "): is there a USB file system at /dev/bus/usb?\n" +
                        dvs128_troubleshooting());
    }
  }
  ~Context() {
    if (ctx != nullptr) libusb_exit(ctx);
  }
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;
};

struct DeviceList {
  libusb_device** list = nullptr;
  std::size_t count = 0;
  explicit DeviceList(libusb_context* ctx) {
    const auto n = libusb_get_device_list(ctx, &list);
    if (n < 0) throw Dvs128Error("cannot list USB devices: " + usb_error(static_cast<int>(n)));
    count = static_cast<std::size_t>(n);
  }
  ~DeviceList() {
    if (list != nullptr) libusb_free_device_list(list, 1);
  }
  DeviceList(const DeviceList&) = delete;
  DeviceList& operator=(const DeviceList&) = delete;
  std::span<libusb_device*> devices() const { return {list, count}; }
};

bool is_dvs128(const libusb_device_descriptor& d) {
  return d.idVendor == dvs128::kVendorId && d.idProduct == dvs128::kProductId;
}

std::string open_problem(int code, int bus, int address) {
  if (code == LIBUSB_ERROR_ACCESS) {
    return "permission denied on " + device_node(bus, address) +
           ": install the udev rule 99-evlife-dvs128.rules (config/ in the source, share/evlife/ when "
           "installed) and replug";
  }
  return "cannot open " + device_node(bus, address) + ": " + usb_error(code);
}

// Reads serial and firmware; `handle` may be null (then serial stays empty).
Dvs128DeviceInfo describe_device(libusb_device* dev, const libusb_device_descriptor& desc,
                                 libusb_device_handle* handle) {
  Dvs128DeviceInfo info;
  info.bus = libusb_get_bus_number(dev);
  info.address = libusb_get_device_address(dev);
  info.firmware_version = desc.bcdDevice & 0xFF;
  if (handle != nullptr && desc.iSerialNumber != 0) {
    unsigned char buf[128] = {};
    const int n = libusb_get_string_descriptor_ascii(handle, desc.iSerialNumber, buf,
                                                     static_cast<int>(sizeof buf));
    if (n > 0) {
      info.serial.assign(reinterpret_cast<const char*>(buf), static_cast<std::size_t>(n));
    } else {
      info.problem = "cannot read the serial number: " + usb_error(n);
    }
  }
  return info;
}

const char* transfer_status_name(int status) {
  switch (status) {
    case LIBUSB_TRANSFER_COMPLETED: return "completed";
    case LIBUSB_TRANSFER_ERROR: return "error";
    case LIBUSB_TRANSFER_TIMED_OUT: return "timed out";
    case LIBUSB_TRANSFER_CANCELLED: return "cancelled";
    case LIBUSB_TRANSFER_STALL: return "stall";
    case LIBUSB_TRANSFER_NO_DEVICE: return "no device";
    case LIBUSB_TRANSFER_OVERFLOW: return "overflow";
    default: return "unknown";
  }
}

}  // namespace

std::string Dvs128DeviceInfo::describe() const {
  std::string s = "DVS128";
  if (!serial.empty()) s += " serial " + serial;
  s += " (bus " + std::to_string(bus) + " device " + std::to_string(address) + ", firmware " +
       std::to_string(firmware_version) + ")";
  return s;
}

std::string dvs128_troubleshooting() {
  return "Check: (1) the cable and that the camera is powered (`lsusb` should list 152a:8400);\n"
         "       (2) permissions: a non-root user needs the udev rule shipped in\n"
         "           config/99-evlife-dvs128.rules (installed: share/evlife/): copy it to\n"
         "           /etc/udev/rules.d/, run `udevadm control --reload-rules` and replug;\n"
         "           or membership of group plugdev;\n"
         "       (3) in a container or VM, that /dev/bus/usb is passed through;\n"
         "       (4) that no other program (jAER, DV, another evlife) holds the camera.";
}

std::vector<UsbDeviceSummary> list_usb_devices() {
  Context c;
  DeviceList list(c.ctx);
  std::vector<UsbDeviceSummary> out;
  for (libusb_device* dev : list.devices()) {
    libusb_device_descriptor d{};
    if (libusb_get_device_descriptor(dev, &d) != 0) continue;
    out.push_back({libusb_get_bus_number(dev), libusb_get_device_address(dev), d.idVendor,
                   d.idProduct});
  }
  return out;
}

std::vector<Dvs128DeviceInfo> list_dvs128_devices() {
  Context c;
  DeviceList list(c.ctx);
  std::vector<Dvs128DeviceInfo> out;
  for (libusb_device* dev : list.devices()) {
    libusb_device_descriptor d{};
    if (libusb_get_device_descriptor(dev, &d) != 0 || !is_dvs128(d)) continue;
    libusb_device_handle* h = nullptr;
    const int r = libusb_open(dev, &h);
    Dvs128DeviceInfo info = describe_device(dev, d, r == 0 ? h : nullptr);
    if (r != 0) info.problem = open_problem(r, info.bus, info.address);
    if (h != nullptr) libusb_close(h);
    out.push_back(std::move(info));
  }
  return out;
}

Dvs128Device::Dvs128Device(const Dvs128DeviceOptions& options)
    : biases_(options.biases), transfer_bytes_(options.transfer_bytes) {
  if (options.transfer_count < 1 || options.transfer_bytes < dvs128::kWordBytes ||
      options.transfer_bytes % dvs128::kWordBytes != 0) {
    throw Dvs128Error("DVS128: need at least one transfer of a positive multiple of 4 bytes");
  }
  if (const int r = libusb_init(&ctx_); r != 0) {
    ctx_ = nullptr;
    throw Dvs128Error("cannot start libusb (" + usb_error(r) + ")\n" + dvs128_troubleshooting());
  }
  try {
    // Find: by serial when asked, else the first DVS128. Remember what else
    // was seen, for a message that helps.
    std::string seen;
    std::string dvs_seen;
    {
      DeviceList list(ctx_);
      for (libusb_device* dev : list.devices()) {
        libusb_device_descriptor d{};
        if (libusb_get_device_descriptor(dev, &d) != 0) continue;
        seen += (seen.empty() ? "" : ", ") + hex4(d.idVendor) + ":" + hex4(d.idProduct) +
                " (bus " + std::to_string(libusb_get_bus_number(dev)) + " device " +
                std::to_string(libusb_get_device_address(dev)) + ")";
        if (!is_dvs128(d)) continue;
        libusb_device_handle* h = nullptr;
        const int r = libusb_open(dev, &h);
        Dvs128DeviceInfo candidate = describe_device(dev, d, r == 0 ? h : nullptr);
        if (r != 0) candidate.problem = open_problem(r, candidate.bus, candidate.address);
        const bool wanted = options.serial.empty() || candidate.serial == options.serial;
        if (r == 0 && wanted && handle_ == nullptr) {
          handle_ = h;
          info_ = candidate;
          continue;
        }
        if (h != nullptr) libusb_close(h);
        dvs_seen += "\n  " + candidate.describe() +
                    (candidate.problem.empty() ? "" : ": " + candidate.problem);
      }
    }
    if (handle_ == nullptr) {
      std::string msg;
      if (dvs_seen.empty()) {
        msg = "no DVS128 camera (USB " + hex4(dvs128::kVendorId) + ":" +
              hex4(dvs128::kProductId) + ") found. USB devices seen: " +
              (seen.empty() ? std::string("none") : seen) + ".";
      } else if (!options.serial.empty()) {
        msg = "no usable DVS128 with serial '" + options.serial + "'. DVS128 cameras seen:" +
              dvs_seen;
      } else {
        msg = "found a DVS128 but cannot open it:" + dvs_seen;
      }
      throw Dvs128Error(msg + "\n" + dvs128_troubleshooting());
    }
    const std::string who = info_.describe();
    if (info_.firmware_version < dvs128::kMinFirmwareVersion) {
      throw Dvs128Error(who + ": firmware too old (version " +
                        std::to_string(info_.firmware_version) + ", need " +
                        std::to_string(dvs128::kMinFirmwareVersion) +
                        " or newer): update it with jAER's firmware tool");
    }
    int config = 0;
    if (const int r = libusb_get_configuration(handle_, &config); r != 0) {
      throw Dvs128Error(who + ": cannot read the active configuration: " + usb_error(r));
    }
    if (config != dvs128::kConfiguration) {
      if (const int r = libusb_set_configuration(handle_, dvs128::kConfiguration); r != 0) {
        throw Dvs128Error(who + ": cannot set configuration 1: " + usb_error(r));
      }
    }
    if (const int r = libusb_claim_interface(handle_, dvs128::kInterface); r != 0) {
      if (r == LIBUSB_ERROR_BUSY) {
        throw Dvs128Error(who + " is busy: another program (jAER, DV, another evlife) has "
                                "claimed it; close that program and retry");
      }
      throw Dvs128Error(who + ": cannot claim interface 0: " + usb_error(r));
    }
    interface_claimed_ = true;
    const auto bias_bytes = biases_.to_bytes();
    vendor_request(dvs128::kRequestSendBiases, bias_bytes, "send biases (0xB8)");

    slots_.resize(static_cast<std::size_t>(options.transfer_count));
    ready_.assign(slots_.size(), 0);
    for (auto& slot : slots_) {
      slot.device = this;
      slot.buffer = std::make_unique<std::uint8_t[]>(static_cast<std::size_t>(transfer_bytes_));
      slot.transfer = libusb_alloc_transfer(0);
      if (slot.transfer == nullptr) throw Dvs128Error(who + ": cannot allocate a USB transfer");
      libusb_fill_bulk_transfer(slot.transfer, handle_, dvs128::kEventEndpoint,
                                slot.buffer.get(), transfer_bytes_, &Dvs128Device::on_transfer,
                                &slot, 0);
    }
  } catch (...) {
    close();
    throw;
  }
}

Dvs128Device::~Dvs128Device() {
  stop();
  close();
}

void Dvs128Device::vendor_request(std::uint8_t request, std::span<const std::uint8_t> data,
                                  const char* what) {
  // libusb takes a non-const buffer even for OUT transfers.
  const int r = libusb_control_transfer(
      handle_, dvs128::kRequestTypeVendorOut, request, 0, 0,
      const_cast<unsigned char*>(data.data()), static_cast<std::uint16_t>(data.size()),
      kControlTimeout_ms);
  if (r < 0 || static_cast<std::size_t>(r) != data.size()) {
    throw Dvs128Error(info_.describe() + ": " + what + " failed: " +
                      (r < 0 ? usb_error(r) : "short transfer"));
  }
}

void Dvs128Device::start() {
  if (state() != Dvs128State::opened) {
    throw Dvs128Error(info_.describe() + ": start() only once, after opening");
  }
  vendor_request(dvs128::kRequestResetTimestamps, {}, "reset timestamps (0xBB)");
  vendor_request(dvs128::kRequestStartTransfer, {}, "start event transfer (0xB3)");
  started_ = true;
  state_.store(Dvs128State::streaming, std::memory_order_release);
  for (auto& slot : slots_) {
    if (!submit(slot)) break;
  }
  // A camera vanishing during this loop is reported through state() once
  // the transfers already submitted (and their data) have been reaped.
  if (in_flight_ == 0) {
    const std::string why = error_;
    stop();
    throw Dvs128Error(why);
  }
}

bool Dvs128Device::submit(Slot& slot) noexcept {
  const int r = libusb_submit_transfer(slot.transfer);
  if (r == 0) {
    slot.in_flight = true;
    ++in_flight_;
    return true;
  }
  if (r == LIBUSB_ERROR_NO_DEVICE) {
    fail(Dvs128State::vanished, info_.describe() + " vanished (unplugged?) while streaming");
  } else {
    fail(Dvs128State::failed,
         info_.describe() + ": cannot submit a bulk transfer on endpoint 0x86: " + usb_error(r));
  }
  return false;
}

void Dvs128Device::fail(Dvs128State state, std::string message) noexcept {
  const Dvs128State now = this->state();
  if (now == Dvs128State::vanished || now == Dvs128State::failed) return;  // first cause wins
  error_ = std::move(message);
  state_.store(state, std::memory_order_release);
}

void Dvs128Device::on_transfer(libusb_transfer* transfer) {
  auto* slot = static_cast<Slot*>(transfer->user_data);
  slot->device->handle_completion(*slot);
}

void Dvs128Device::handle_completion(Slot& slot) noexcept {
  slot.in_flight = false;
  --in_flight_;
  const libusb_transfer& t = *slot.transfer;
  switch (t.status) {
    case LIBUSB_TRANSFER_COMPLETED:
    case LIBUSB_TRANSFER_TIMED_OUT:  // timeout 0: not expected, but data may be there
      ++transfers_completed_;
      if (t.actual_length > 0) {
        bytes_received_ += static_cast<std::uint64_t>(t.actual_length);
        push_ready(slot);
      } else if (state() == Dvs128State::streaming) {
        submit(slot);
      }
      return;
    case LIBUSB_TRANSFER_CANCELLED:
      // Cancelled by stop(): keep whatever part of it had already arrived.
      if (t.actual_length > 0) {
        bytes_received_ += static_cast<std::uint64_t>(t.actual_length);
        push_ready(slot);
      }
      return;
    case LIBUSB_TRANSFER_NO_DEVICE:
      fail(Dvs128State::vanished, info_.describe() + " vanished (unplugged?) while streaming");
      return;
    default:
      // Data of a failed transfer is lost: count it, then try to carry on;
      // if the device is gone the resubmission reports it.
      transfers_failed_.fetch_add(1, std::memory_order_relaxed);
      bytes_lost_.fetch_add(static_cast<std::uint64_t>(std::max(t.actual_length, 0)), std::memory_order_relaxed);
      if (state() == Dvs128State::streaming) {
        if (t.status == LIBUSB_TRANSFER_STALL) libusb_clear_halt(handle_, dvs128::kEventEndpoint);
        if (!submit(slot) && state() == Dvs128State::failed) {
          error_ += std::string(" (after a transfer ") + transfer_status_name(t.status) + ")";
        }
      }
      return;
  }
}

void Dvs128Device::push_ready(Slot& slot) noexcept {
  slot.completed_ns = steady_now_ns();
  const int tail = (ready_head_ + ready_count_) % static_cast<int>(ready_.size());
  ready_[static_cast<std::size_t>(tail)] = static_cast<int>(&slot - slots_.data());
  ++ready_count_;  // at most one entry per slot: never exceeds the ring's capacity
}

void Dvs128Device::handle_events(std::chrono::microseconds timeout) noexcept {
  if (ctx_ == nullptr) return;
  timeval tv{};
  tv.tv_sec = static_cast<decltype(tv.tv_sec)>(timeout.count() / 1000000);
  tv.tv_usec = static_cast<decltype(tv.tv_usec)>(timeout.count() % 1000000);
  libusb_handle_events_timeout_completed(ctx_, &tv, nullptr);
}

Dvs128Device::Chunk Dvs128Device::front() const noexcept {
  if (ready_count_ == 0) return {};
  const Slot& slot = slots_[static_cast<std::size_t>(ready_[static_cast<std::size_t>(ready_head_)])];
  return {{slot.buffer.get(), static_cast<std::size_t>(slot.transfer->actual_length)},
          slot.completed_ns};
}

void Dvs128Device::release_front() noexcept {
  if (ready_count_ == 0) return;
  Slot& slot = slots_[static_cast<std::size_t>(ready_[static_cast<std::size_t>(ready_head_)])];
  ready_head_ = (ready_head_ + 1) % static_cast<int>(ready_.size());
  --ready_count_;
  if (state() == Dvs128State::streaming) submit(slot);
}

void Dvs128Device::stop() noexcept {
  if (handle_ == nullptr) return;
  if (state() == Dvs128State::streaming || state() == Dvs128State::opened) {
    state_.store(Dvs128State::stopped, std::memory_order_release);
  }
  for (auto& slot : slots_) {
    if (slot.in_flight) libusb_cancel_transfer(slot.transfer);
  }
  const auto deadline = std::chrono::steady_clock::now() + kStopReapBudget;
  while (in_flight_ > 0 && std::chrono::steady_clock::now() < deadline) {
    handle_events(std::chrono::milliseconds(10));
  }
  if (started_ && state() != Dvs128State::vanished) {
    started_ = false;
    // Best effort: the camera may already be gone.
    libusb_control_transfer(handle_, dvs128::kRequestTypeVendorOut,
                            dvs128::kRequestStopTransfer, 0, 0, nullptr, 0, kControlTimeout_ms);
  }
  if (interface_claimed_) {
    libusb_release_interface(handle_, dvs128::kInterface);
    interface_claimed_ = false;
  }
}

void Dvs128Device::close() noexcept {
  for (auto& slot : slots_) {
    // A transfer still in flight after the reap budget must not be freed
    // under libusb's feet; closing the handle below reaps it.
    if (slot.transfer != nullptr && !slot.in_flight) {
      libusb_free_transfer(slot.transfer);
      slot.transfer = nullptr;
    }
  }
  if (interface_claimed_) {
    libusb_release_interface(handle_, dvs128::kInterface);
    interface_claimed_ = false;
  }
  if (handle_ != nullptr) {
    libusb_close(handle_);
    handle_ = nullptr;
  }
  if (ctx_ != nullptr) {
    libusb_exit(ctx_);
    ctx_ = nullptr;
  }
}

}  // namespace evlife::io
