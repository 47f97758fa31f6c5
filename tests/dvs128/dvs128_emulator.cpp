#include "dvs128_emulator.h"

#include <sys/ioctl.h>
#include <linux/usbdevice_fs.h>
#include <umockdev.h>

#include <algorithm>
#include <cerrno>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <thread>

namespace evlife::testing {

namespace {

std::string hex_bytes(const std::vector<std::uint8_t>& bytes) {
  std::string s;
  char buf[3];
  for (auto b : bytes) {
    std::snprintf(buf, sizeof buf, "%02x", b);
    s += buf;
  }
  return s;
}

// Device + configuration + interface + 2 endpoint descriptors of a DVS128
// (values from the FX2 firmware: 0x86 bulk IN 512 B for events, 0x81 64 B).
std::vector<std::uint8_t> dvs128_descriptors(std::uint16_t vid, std::uint16_t pid, int bcd) {
  return {0x12, 0x01, 0x00, 0x02, 0x00, 0x00, 0x00, 0x40,
          static_cast<std::uint8_t>(vid & 0xFF), static_cast<std::uint8_t>(vid >> 8),
          static_cast<std::uint8_t>(pid & 0xFF), static_cast<std::uint8_t>(pid >> 8),
          static_cast<std::uint8_t>(bcd & 0xFF), static_cast<std::uint8_t>(bcd >> 8),
          0x01, 0x02, 0x03, 0x01,
          // configuration 1: 32 bytes total, 1 interface, bus powered, 500 mA
          0x09, 0x02, 0x20, 0x00, 0x01, 0x01, 0x00, 0x80, 0xFA,
          // interface 0, 2 endpoints, vendor class 0xFF
          0x09, 0x04, 0x00, 0x00, 0x02, 0xFF, 0x00, 0x00, 0x00,
          0x07, 0x05, 0x86, 0x02, 0x00, 0x02, 0x00,
          0x07, 0x05, 0x81, 0x02, 0x40, 0x00, 0x00};
}

std::vector<std::uint8_t> string_descriptor(const std::string& ascii) {
  std::vector<std::uint8_t> d{static_cast<std::uint8_t>(2 + 2 * ascii.size()), 0x03};
  for (char c : ascii) {
    d.push_back(static_cast<std::uint8_t>(c));
    d.push_back(0);
  }
  return d;
}

}  // namespace

// ---------------------------------------------------------------------------
// The usbdevfs emulation of one camera.

struct PendingUrb {
  UMockdevIoctlData* urb = nullptr;     // owned ref: the client's struct usbdevfs_urb
  UMockdevIoctlData* buffer = nullptr;  // owned ref: its data buffer
  usbdevfs_urb* fields() const { return reinterpret_cast<usbdevfs_urb*>(urb->data); }
  void release() {
    if (buffer != nullptr) g_object_unref(buffer);
    if (urb != nullptr) g_object_unref(urb);
    urb = buffer = nullptr;
  }
};

struct EmulatedDvs128::Impl {
  std::string serial;
  std::string devnode;
  UMockdevIoctlBase* handler = nullptr;
  mutable std::mutex mutex;
  std::deque<std::vector<std::uint8_t>> packets;
  std::deque<PendingUrb> bulk_waiting;  // submitted on 0x86, no data yet
  std::deque<PendingUrb> completed;     // ready to be reaped
  std::vector<ControlRequest> controls;
  bool unplugged = false;
  bool busy = false;
  bool strings_stall = false;
  int fail_next_errno = 0;
  int claims = 0;
  int releases = 0;
  int urbs_completed = 0;
  int urbs_discarded = 0;

  gboolean handle(UMockdevIoctlClient* client);
  void submit(UMockdevIoctlClient* client, UMockdevIoctlData* arg);
  void reap(UMockdevIoctlClient* client, UMockdevIoctlData* arg);
  void match_packets();
  void answer_control(PendingUrb& u);
};

namespace {
gboolean on_handle_ioctl(UMockdevIoctlBase*, UMockdevIoctlClient* client, gpointer self) {
  return static_cast<EmulatedDvs128::Impl*>(self)->handle(client);
}
}  // namespace

gboolean EmulatedDvs128::Impl::handle(UMockdevIoctlClient* client) {
  std::lock_guard lock(mutex);
  const gulong request = umockdev_ioctl_client_get_request(client);
  UMockdevIoctlData* arg = umockdev_ioctl_client_get_arg(client);
  GError* err = nullptr;
  auto resolve_uint = [&]() -> unsigned {
    UMockdevIoctlData* d = umockdev_ioctl_data_resolve(arg, 0, sizeof(unsigned), &err);
    unsigned v = 0;
    if (d != nullptr) {
      std::memcpy(&v, d->data, sizeof v);
      g_object_unref(d);
    }
    return v;
  };
  switch (request) {
    case USBDEVFS_GET_CAPABILITIES: {
      UMockdevIoctlData* d = umockdev_ioctl_data_resolve(arg, 0, sizeof(std::uint32_t), &err);
      const std::uint32_t caps = USBDEVFS_CAP_BULK_CONTINUATION | USBDEVFS_CAP_NO_PACKET_SIZE_LIM |
                                 USBDEVFS_CAP_REAP_AFTER_DISCONNECT | USBDEVFS_CAP_ZERO_PACKET;
      if (d != nullptr) {
        std::memcpy(d->data, &caps, sizeof caps);
        g_object_unref(d);
      }
      umockdev_ioctl_client_complete(client, 0, 0);
      return TRUE;
    }
    case USBDEVFS_CLAIMINTERFACE:
    case USBDEVFS_RELEASEINTERFACE:
    case USBDEVFS_SETCONFIGURATION:
    case USBDEVFS_CLEAR_HALT:
    case USBDEVFS_RESETEP: {
      (void)resolve_uint();
      if (unplugged) {
        umockdev_ioctl_client_complete(client, -1, ENODEV);
        return TRUE;
      }
      if (request == USBDEVFS_CLAIMINTERFACE && busy) {
        umockdev_ioctl_client_complete(client, -1, EBUSY);
        return TRUE;
      }
      if (request == USBDEVFS_CLAIMINTERFACE) ++claims;
      if (request == USBDEVFS_RELEASEINTERFACE) ++releases;
      umockdev_ioctl_client_complete(client, 0, 0);
      return TRUE;
    }
    case USBDEVFS_SUBMITURB:
      submit(client, arg);
      return TRUE;
    case USBDEVFS_DISCARDURB: {
      // Size-0 ioctl: the argument IS the client's URB address; never resolve it.
      gulong addr = 0;
      std::memcpy(&addr, arg->data, sizeof addr);
      auto it = std::find_if(bulk_waiting.begin(), bulk_waiting.end(),
                             [&](const PendingUrb& u) { return u.urb->client_addr == addr; });
      if (it == bulk_waiting.end()) {
        umockdev_ioctl_client_complete(client, -1, EINVAL);
        return TRUE;
      }
      it->fields()->status = -ENOENT;
      it->fields()->actual_length = 0;
      completed.push_back(*it);
      bulk_waiting.erase(it);
      ++urbs_discarded;
      umockdev_ioctl_client_complete(client, 0, 0);
      return TRUE;
    }
    case USBDEVFS_REAPURB:
    case USBDEVFS_REAPURBNDELAY:
      reap(client, arg);
      return TRUE;
    default:
      umockdev_ioctl_client_complete(client, -1, unplugged ? ENODEV : ENOTTY);
      return TRUE;
  }
}

void EmulatedDvs128::Impl::submit(UMockdevIoctlClient* client, UMockdevIoctlData* arg) {
  GError* err = nullptr;
  if (unplugged) {
    umockdev_ioctl_client_complete(client, -1, ENODEV);
    return;
  }
  PendingUrb u;
  u.urb = umockdev_ioctl_data_resolve(arg, 0, sizeof(usbdevfs_urb), &err);
  if (u.urb == nullptr) {
    umockdev_ioctl_client_complete(client, -1, EFAULT);
    return;
  }
  const auto length = static_cast<gsize>(u.fields()->buffer_length);
  if (length > 0) {
    u.buffer = umockdev_ioctl_data_resolve(u.urb, offsetof(usbdevfs_urb, buffer), length, &err);
  }
  const unsigned char type = u.fields()->type;
  const unsigned char endpoint = u.fields()->endpoint;
  if (type == USBDEVFS_URB_TYPE_CONTROL) {
    answer_control(u);
    completed.push_back(u);
  } else if (type == USBDEVFS_URB_TYPE_BULK && endpoint == 0x86 && u.buffer != nullptr) {
    bulk_waiting.push_back(u);
    match_packets();
  } else {
    bulk_waiting.push_back(u);  // e.g. 0x81: never answered, only cancelled
  }
  umockdev_ioctl_client_complete(client, 0, 0);
}

void EmulatedDvs128::Impl::answer_control(PendingUrb& u) {
  usbdevfs_urb* f = u.fields();
  const std::uint8_t* setup = u.buffer->data;
  ControlRequest c;
  c.request_type = setup[0];
  c.request = setup[1];
  c.value = static_cast<std::uint16_t>(setup[2] | (setup[3] << 8));
  c.index = static_cast<std::uint16_t>(setup[4] | (setup[5] << 8));
  const int w_length = setup[6] | (setup[7] << 8);
  f->status = 0;
  if ((c.request_type & 0x80) == 0) {  // OUT: record the data stage
    c.data.assign(setup + 8, setup + 8 + w_length);
    f->actual_length = w_length;
  } else if (c.request_type == 0x80 && c.request == 0x06 && (c.value >> 8) == 0x03 && !strings_stall) {
    // GET_DESCRIPTOR(string): 0 = languages, 1 manufacturer, 2 product, 3 serial.
    const int index = c.value & 0xFF;
    std::vector<std::uint8_t> d = index == 0   ? std::vector<std::uint8_t>{4, 3, 0x09, 0x04}
                                  : index == 1 ? string_descriptor("iniLabs")
                                  : index == 2 ? string_descriptor("DVS128")
                                               : string_descriptor(serial);
    const int n = std::min<int>(w_length, static_cast<int>(d.size()));
    std::memcpy(u.buffer->data + 8, d.data(), static_cast<std::size_t>(n));
    f->actual_length = n;
  } else {
    f->status = -EPIPE;  // stall: not a request this camera answers
    f->actual_length = 0;
  }
  controls.push_back(std::move(c));
}

void EmulatedDvs128::Impl::match_packets() {
  while (!packets.empty() && !bulk_waiting.empty()) {
    auto it = std::find_if(bulk_waiting.begin(), bulk_waiting.end(), [](const PendingUrb& u) {
      return u.fields()->endpoint == 0x86 && u.buffer != nullptr;
    });
    if (it == bulk_waiting.end()) return;
    PendingUrb u = *it;
    bulk_waiting.erase(it);
    std::vector<std::uint8_t>& p = packets.front();
    const auto n = std::min<std::size_t>(p.size(), static_cast<std::size_t>(u.buffer->data_len));
    std::memcpy(u.buffer->data, p.data(), n);
    u.fields()->status = -fail_next_errno;
    u.fields()->actual_length = fail_next_errno != 0 ? 0 : static_cast<int>(n);
    fail_next_errno = 0;
    if (n == p.size()) {
      packets.pop_front();
    } else {
      p.erase(p.begin(), p.begin() + static_cast<std::ptrdiff_t>(n));
    }
    completed.push_back(u);
    ++urbs_completed;
  }
}

void EmulatedDvs128::Impl::reap(UMockdevIoctlClient* client, UMockdevIoctlData* arg) {
  match_packets();
  if (unplugged && packets.empty()) {
    for (auto& u : bulk_waiting) {
      u.fields()->status = -ESHUTDOWN;
      u.fields()->actual_length = 0;
      completed.push_back(u);
    }
    bulk_waiting.clear();
  }
  if (completed.empty()) {
    umockdev_ioctl_client_complete(client, -1, unplugged ? ENODEV : EAGAIN);
    return;
  }
  PendingUrb u = completed.front();
  completed.pop_front();
  GError* err = nullptr;
  UMockdevIoctlData* ptr = umockdev_ioctl_data_resolve(arg, 0, sizeof(void*), &err);
  if (ptr == nullptr) {
    u.release();
    umockdev_ioctl_client_complete(client, -1, EFAULT);
    return;
  }
  umockdev_ioctl_data_set_ptr(ptr, 0, u.urb);  // the client's pointer now names its URB
  g_object_unref(ptr);
  umockdev_ioctl_client_complete(client, 0, 0);  // flushes URB fields and buffer back
  u.release();
}

EmulatedDvs128::EmulatedDvs128(std::string serial, std::string devnode)
    : impl_(std::make_unique<Impl>()) {
  impl_->serial = std::move(serial);
  impl_->devnode = std::move(devnode);
  impl_->handler = umockdev_ioctl_base_new();
  g_signal_connect(impl_->handler, "handle-ioctl", G_CALLBACK(on_handle_ioctl), impl_.get());
}

EmulatedDvs128::~EmulatedDvs128() {
  std::lock_guard lock(impl_->mutex);
  for (auto& u : impl_->bulk_waiting) u.release();
  for (auto& u : impl_->completed) u.release();
}

void EmulatedDvs128::push_packet(std::vector<std::uint8_t> bytes) {
  std::lock_guard lock(impl_->mutex);
  impl_->packets.push_back(std::move(bytes));
}

std::size_t EmulatedDvs128::queued_packets() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->packets.size();
}

int EmulatedDvs128::waiting_urbs() const {
  std::lock_guard lock(impl_->mutex);
  return static_cast<int>(std::count_if(impl_->bulk_waiting.begin(), impl_->bulk_waiting.end(),
                                        [](const PendingUrb& u) {
                                          return u.fields()->endpoint == 0x86;
                                        }));
}

void EmulatedDvs128::unplug() {
  std::lock_guard lock(impl_->mutex);
  impl_->unplugged = true;
}

void EmulatedDvs128::set_busy(bool busy) {
  std::lock_guard lock(impl_->mutex);
  impl_->busy = busy;
}

void EmulatedDvs128::set_strings_stall(bool stall) {
  std::lock_guard lock(impl_->mutex);
  impl_->strings_stall = stall;
}

void EmulatedDvs128::fail_next_packet(int errno_value) {
  std::lock_guard lock(impl_->mutex);
  impl_->fail_next_errno = errno_value;
}

std::vector<ControlRequest> EmulatedDvs128::control_requests() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->controls;
}

std::vector<std::uint8_t> EmulatedDvs128::vendor_requests() const {
  std::lock_guard lock(impl_->mutex);
  std::vector<std::uint8_t> out;
  for (const auto& c : impl_->controls) {
    if (c.request_type == 0x40) out.push_back(c.request);
  }
  return out;
}

int EmulatedDvs128::claims() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->claims;
}
int EmulatedDvs128::releases() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->releases;
}
int EmulatedDvs128::urbs_completed() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->urbs_completed;
}
int EmulatedDvs128::urbs_discarded() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->urbs_discarded;
}

bool EmulatedDvs128::wait_for(const std::function<bool()>& pred,
                              std::chrono::milliseconds timeout) const {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!pred()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

// ---------------------------------------------------------------------------

struct UsbTestbed::Impl {
  UMockdevTestbed* testbed = nullptr;
};

UsbTestbed::UsbTestbed() : impl_(std::make_unique<Impl>()) {
  const char* preload = std::getenv("LD_PRELOAD");
  if (preload == nullptr || std::strstr(preload, "umockdev-preload") == nullptr) {
    throw std::runtime_error(
        "not running under umockdev-wrapper: run this test as `umockdev-wrapper <test>` "
        "(ctest does it)");
  }
  impl_->testbed = umockdev_testbed_new();
}

UsbTestbed::~UsbTestbed() {
  for (auto& cam : cameras_) {
    GError* err = nullptr;
    umockdev_testbed_detach_ioctl(impl_->testbed, cam->impl().devnode.c_str(), &err);
    if (err != nullptr) g_error_free(err);
    g_object_unref(cam->impl().handler);
  }
  cameras_.clear();
  g_object_unref(impl_->testbed);
}

void UsbTestbed::add_description(std::uint16_t vid, std::uint16_t pid, int bcd_device, int bus,
                                 int address, const std::string& descriptor_hex) {
  char buf[2048];
  std::snprintf(buf, sizeof buf,
                "P: /devices/pci0000:00/0000:00:14.0/usb%d/%d-%d\n"
                "N: bus/usb/%03d/%03d\n"
                "E: SUBSYSTEM=usb\n"
                "E: DEVTYPE=usb_device\n"
                "E: DEVNAME=/dev/bus/usb/%03d/%03d\n"
                "E: BUSNUM=%03d\n"
                "E: DEVNUM=%03d\n"
                "E: PRODUCT=%x/%x/%x\n"
                "A: busnum=%d\\n\n"
                "A: devnum=%d\\n\n"
                "A: speed=480\\n\n"
                "A: bConfigurationValue=1\\n\n"
                "A: idVendor=%04x\\n\n"
                "A: idProduct=%04x\\n\n"
                "H: descriptors=%s\n",
                bus, bus, address, bus, address, bus, address, bus, address, vid, pid, bcd_device,
                bus, address, vid, pid, descriptor_hex.c_str());
  GError* err = nullptr;
  if (!umockdev_testbed_add_from_string(impl_->testbed, buf, &err)) {
    std::string why = err != nullptr ? err->message : "unknown";
    if (err != nullptr) g_error_free(err);
    throw std::runtime_error("umockdev: cannot add device: " + why);
  }
}

EmulatedDvs128& UsbTestbed::add_dvs128(std::string serial, int firmware_version, int bus,
                                      int address) {
  if (firmware_version == 14 && bus == 1 && address == 2) {
    // The default camera comes from the fixture file (also usable by hand:
    // `umockdev-run -d tests/dvs128/dvs128.umockdev -- evlife devices`).
    GError* err = nullptr;
    if (!umockdev_testbed_add_from_file(impl_->testbed, EVLIFE_DVS128_FIXTURE, &err)) {
      std::string why = err != nullptr ? err->message : "unknown";
      if (err != nullptr) g_error_free(err);
      throw std::runtime_error(std::string("umockdev: cannot load ") + EVLIFE_DVS128_FIXTURE +
                               ": " + why);
    }
  } else {  // variants (other address, old firmware): same descriptors, generated
    add_description(0x152A, 0x8400, firmware_version, bus, address,
                    hex_bytes(dvs128_descriptors(0x152A, 0x8400, firmware_version)));
  }
  char devnode[64];
  std::snprintf(devnode, sizeof devnode, "/dev/bus/usb/%03d/%03d", bus, address);
  cameras_.push_back(std::make_unique<EmulatedDvs128>(std::move(serial), devnode));
  GError* err = nullptr;
  if (!umockdev_testbed_attach_ioctl(impl_->testbed, devnode, cameras_.back()->impl().handler,
                                     &err)) {
    std::string why = err != nullptr ? err->message : "unknown";
    if (err != nullptr) g_error_free(err);
    throw std::runtime_error("umockdev: cannot attach the usbdevfs emulation: " + why);
  }
  return *cameras_.back();
}

void UsbTestbed::add_other_device(std::uint16_t vendor_id, std::uint16_t product_id, int bus,
                                  int address) {
  auto d = dvs128_descriptors(vendor_id, product_id, 0x0100);
  add_description(vendor_id, product_id, 0x0100, bus, address, hex_bytes(d));
}

std::vector<std::uint8_t> words_to_bytes(const std::vector<std::uint32_t>& words) {
  std::vector<std::uint8_t> out;
  out.reserve(words.size() * 4);
  for (std::uint32_t w : words) {
    for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::uint8_t>(w >> (8 * i)));
  }
  return out;
}

std::uint32_t dvs128_word(int raw_x, int raw_y, bool raw_polarity_bit, int ts14_us) {
  const std::uint32_t address = (static_cast<std::uint32_t>(raw_y & 0x7F) << 8) |
                                (static_cast<std::uint32_t>(raw_x & 0x7F) << 1) |
                                (raw_polarity_bit ? 1u : 0u);
  return address | (static_cast<std::uint32_t>(ts14_us & 0x3FFF) << 16);
}

}  // namespace evlife::testing
