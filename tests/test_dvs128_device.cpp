// The DVS128 device layer (io/dvs128_device) through the REAL libusb code
// path, against umockdev's in-process usbdevfs emulation (dvs128/). Runs
// under umockdev-wrapper (ctest's launcher). Expected values are written out
// by hand from the protocol (bias bytes, request codes), never produced by
// the code under test.
#include <gtest/gtest.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <vector>

#include "dvs128_emulator.h"
#include "evlife/io/dvs128_device.h"

namespace {

using evlife::io::Dvs128Device;
using evlife::io::Dvs128DeviceOptions;
using evlife::io::Dvs128Error;
using evlife::io::Dvs128State;
using evlife::testing::UsbTestbed;
using namespace std::chrono_literals;

// Default biases, 24-bit big endian, order CAS..PR (worked out by hand).
const std::vector<std::uint8_t> kDefaultBiasBytes = {
    0x00, 0x07, 0xC8, 0x10, 0xE9, 0x8C, 0xFF, 0xFF, 0xFF, 0x7C, 0x7F, 0xF5,
    0x00, 0x00, 0x84, 0x04, 0xB9, 0x56, 0x00, 0x03, 0xC9, 0xFF, 0xFF, 0xFF,
    0x03, 0x34, 0x4C, 0x00, 0x33, 0x45, 0x00, 0x01, 0x0F, 0x00, 0x00, 0xD9};

// Drives the device until pred() or a bounded time passed.
template <typename Pred>
bool pump(Dvs128Device& dev, Pred pred, std::chrono::milliseconds budget = 2000ms) {
  const auto deadline = std::chrono::steady_clock::now() + budget;
  while (!pred()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    dev.handle_events(1ms);
  }
  return true;
}

std::vector<std::uint8_t> drain(Dvs128Device& dev) {
  std::vector<std::uint8_t> bytes;
  while (dev.has_data()) {
    const auto chunk = dev.front();
    bytes.insert(bytes.end(), chunk.bytes.begin(), chunk.bytes.end());
    dev.release_front();
  }
  return bytes;
}

TEST(Dvs128Device, EnumeratesCamerasWithSerialAndOtherDevices) {
  UsbTestbed bed;
  bed.add_dvs128("SN-0042", 14, 1, 2);
  bed.add_other_device(0x1d6b, 0x0002, 1, 1);
  const auto cams = evlife::io::list_dvs128_devices();
  ASSERT_EQ(cams.size(), 1u);
  EXPECT_EQ(cams[0].serial, "SN-0042");
  EXPECT_EQ(cams[0].bus, 1);
  EXPECT_EQ(cams[0].address, 2);
  EXPECT_EQ(cams[0].firmware_version, 14);
  EXPECT_TRUE(cams[0].problem.empty()) << cams[0].problem;
  EXPECT_EQ(evlife::io::list_usb_devices().size(), 2u);
}

TEST(Dvs128Device, SendsExactBiasesThenResetAndStartThenStop) {
  UsbTestbed bed;
  auto& cam = bed.add_dvs128();
  {
    Dvs128Device dev(Dvs128DeviceOptions{});
    EXPECT_EQ(cam.claims(), 1);
    dev.start();
    EXPECT_EQ(dev.state(), Dvs128State::streaming);
    EXPECT_EQ(dev.transfers_in_flight(), 8);
    ASSERT_TRUE(cam.wait_for([&] { return cam.waiting_urbs() == 8; }));
    dev.stop();
    EXPECT_EQ(dev.transfers_in_flight(), 0);
    EXPECT_EQ(cam.urbs_discarded(), 8);
    EXPECT_EQ(cam.releases(), 1);
  }
  const std::vector<std::uint8_t> expected_order = {0xB8, 0xBB, 0xB3, 0xB4};
  EXPECT_EQ(cam.vendor_requests(), expected_order);
  for (const auto& c : cam.control_requests()) {
    if (c.request_type != 0x40) continue;
    EXPECT_EQ(c.value, 0);
    EXPECT_EQ(c.index, 0);
    if (c.request == 0xB8) {
      EXPECT_EQ(c.data, kDefaultBiasBytes);
    } else {
      EXPECT_TRUE(c.data.empty());
    }
  }
}

TEST(Dvs128Device, SendsBiasesGivenByTheUser) {
  UsbTestbed bed;
  auto& cam = bed.add_dvs128();
  Dvs128DeviceOptions opt;
  opt.biases.values[0] = 0x123456;   // cas
  opt.biases.values[11] = 0xABCDEF;  // pr
  Dvs128Device dev(opt);
  auto expected = kDefaultBiasBytes;
  expected[0] = 0x12, expected[1] = 0x34, expected[2] = 0x56;
  expected[33] = 0xAB, expected[34] = 0xCD, expected[35] = 0xEF;
  const auto controls = cam.control_requests();
  bool seen = false;
  for (const auto& c : controls) {
    if (c.request_type == 0x40 && c.request == 0xB8) {
      EXPECT_EQ(c.data, expected);
      seen = true;
    }
  }
  EXPECT_TRUE(seen);
}

TEST(Dvs128Device, DeliversBulkPacketsInOrder) {
  UsbTestbed bed;
  auto& cam = bed.add_dvs128();
  Dvs128Device dev(Dvs128DeviceOptions{});
  dev.start();
  std::vector<std::uint8_t> sent;
  for (int p = 0; p < 20; ++p) {  // more packets than transfers: resubmission must work
    std::vector<std::uint8_t> packet(512);
    for (std::size_t i = 0; i < packet.size(); ++i) {
      packet[i] = static_cast<std::uint8_t>(p * 7 + static_cast<int>(i));
    }
    sent.insert(sent.end(), packet.begin(), packet.end());
    cam.push_packet(packet);
  }
  std::vector<std::uint8_t> got;
  ASSERT_TRUE(pump(dev, [&] {
    const auto more = drain(dev);
    got.insert(got.end(), more.begin(), more.end());
    return got.size() >= sent.size();
  }));
  EXPECT_EQ(got, sent);
  EXPECT_EQ(dev.bytes_received(), sent.size());
  EXPECT_EQ(dev.transfers_failed(), 0u);
}

TEST(Dvs128Device, SelectsTheCameraBySerialNumber) {
  UsbTestbed bed;
  auto& a = bed.add_dvs128("AAA", 14, 1, 2);
  auto& b = bed.add_dvs128("BBB", 14, 1, 3);
  Dvs128DeviceOptions opt;
  opt.serial = "BBB";
  Dvs128Device dev(opt);
  EXPECT_EQ(dev.info().serial, "BBB");
  EXPECT_EQ(dev.info().address, 3);
  EXPECT_EQ(b.claims(), 1);
  EXPECT_EQ(a.claims(), 0);
  EXPECT_TRUE(a.vendor_requests().empty());

  opt.serial = "CCC";
  try {
    Dvs128Device missing(opt);
    FAIL() << "opened a camera that is not there";
  } catch (const Dvs128Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("'CCC'"), std::string::npos) << m;
    EXPECT_NE(m.find("AAA"), std::string::npos) << m;  // lists what it found
  }
}

TEST(Dvs128Device, NoCameraGivesAClearErrorListingWhatWasFound) {
  UsbTestbed bed;
  bed.add_other_device(0x046d, 0xc52b, 1, 4);
  try {
    Dvs128Device dev(Dvs128DeviceOptions{});
    FAIL() << "opened a camera that is not there";
  } catch (const Dvs128Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("no DVS128"), std::string::npos) << m;
    EXPECT_NE(m.find("152a:8400"), std::string::npos) << m;
    EXPECT_NE(m.find("046d:c52b"), std::string::npos) << m;  // what was found
    EXPECT_NE(m.find("cable"), std::string::npos) << m;
    EXPECT_NE(m.find("permission"), std::string::npos) << m;
    EXPECT_NE(m.find("99-evlife-dvs128.rules"), std::string::npos) << m;
  }
}

TEST(Dvs128Device, RefusesFirmwareOlderThan14) {
  UsbTestbed bed;
  auto& cam = bed.add_dvs128("OLD", 13);
  try {
    Dvs128Device dev(Dvs128DeviceOptions{});
    FAIL() << "accepted firmware 13";
  } catch (const Dvs128Error& e) {
    EXPECT_NE(std::string(e.what()).find("firmware too old"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(cam.vendor_requests().empty());  // nothing sent to it
}

TEST(Dvs128Device, BusyCameraIsAClearError) {
  UsbTestbed bed;
  auto& cam = bed.add_dvs128();
  cam.set_busy(true);
  try {
    Dvs128Device dev(Dvs128DeviceOptions{});
    FAIL() << "claimed a busy camera";
  } catch (const Dvs128Error& e) {
    EXPECT_NE(std::string(e.what()).find("busy"), std::string::npos) << e.what();
  }
}

TEST(Dvs128Device, ATransferErrorIsCountedAndStreamingGoesOn) {
  UsbTestbed bed;
  auto& cam = bed.add_dvs128();
  Dvs128Device dev(Dvs128DeviceOptions{});
  dev.start();
  cam.fail_next_packet(EPROTO);
  cam.push_packet(std::vector<std::uint8_t>(64, 0xAA));  // lost in the failed transfer
  cam.push_packet(std::vector<std::uint8_t>(64, 0xBB));
  std::vector<std::uint8_t> got;
  ASSERT_TRUE(pump(dev, [&] {
    const auto more = drain(dev);
    got.insert(got.end(), more.begin(), more.end());
    return got.size() >= 64;
  }));
  EXPECT_EQ(got, std::vector<std::uint8_t>(64, 0xBB));
  EXPECT_EQ(dev.transfers_failed(), 1u);
  EXPECT_EQ(dev.state(), Dvs128State::streaming);
  EXPECT_EQ(dev.transfers_in_flight(), 8);
}

TEST(Dvs128Device, UnplugMidStreamDeliversWhatWasReadThenReportsVanished) {
  UsbTestbed bed;
  auto& cam = bed.add_dvs128();
  Dvs128Device dev(Dvs128DeviceOptions{});
  dev.start();
  std::vector<std::uint8_t> sent;
  for (int p = 0; p < 5; ++p) {
    std::vector<std::uint8_t> packet(256, static_cast<std::uint8_t>(p + 1));
    sent.insert(sent.end(), packet.begin(), packet.end());
    cam.push_packet(packet);
  }
  cam.unplug();
  std::vector<std::uint8_t> got;
  ASSERT_TRUE(pump(dev, [&] {
    const auto more = drain(dev);
    got.insert(got.end(), more.begin(), more.end());
    return dev.state() == Dvs128State::vanished && dev.transfers_in_flight() == 0;
  }));
  const auto rest = drain(dev);
  got.insert(got.end(), rest.begin(), rest.end());
  EXPECT_EQ(got, sent);
  EXPECT_NE(dev.error_message().find("vanished"), std::string::npos) << dev.error_message();
  dev.stop();  // no hang, no STOP to a device that is gone
  const auto req = cam.vendor_requests();
  EXPECT_EQ(std::count(req.begin(), req.end(), 0xB4), 0);
}

}  // namespace
