// DVS128 USB protocol constants (iniVation/inilabs FX2 firmware), as used by
// libcaer (src/dvs128.c) and jAER (CypressFX2DVS128HardwareInterface). Facts
// only; the decoder and the device layer build on them.
#pragma once

#include <cstdint>

namespace evlife::io::dvs128 {

inline constexpr std::uint16_t kVendorId = 0x152A;
inline constexpr std::uint16_t kProductId = 0x8400;
/// Firmware version = low byte of bcdDevice; libcaer refuses older than 14.
inline constexpr int kMinFirmwareVersion = 14;

inline constexpr int kConfiguration = 1;
inline constexpr int kInterface = 0;
inline constexpr unsigned char kEventEndpoint = 0x86;  ///< bulk IN, 4-byte event words

/// Vendor requests (bmRequestType 0x40 = host-to-device, vendor, device; wValue = wIndex = 0).
inline constexpr std::uint8_t kRequestTypeVendorOut = 0x40;
inline constexpr std::uint8_t kRequestStartTransfer = 0xB3;
inline constexpr std::uint8_t kRequestStopTransfer = 0xB4;
inline constexpr std::uint8_t kRequestSendBiases = 0xB8;
inline constexpr std::uint8_t kRequestResetTimestamps = 0xBB;
inline constexpr std::uint8_t kRequestArrayReset = 0xBD;
inline constexpr std::uint8_t kRequestTimestampMaster = 0xBE;

/// libcaer's transfer setup: 8 asynchronous bulk transfers of 4096 B, timeout 0.
inline constexpr int kDefaultTransferCount = 8;
inline constexpr int kDefaultTransferBytes = 4096;

inline constexpr int kWidth = 128;
inline constexpr int kHeight = 128;

/// Event word layout (4 bytes, little endian):
///   bytes 0-1 address: bit 0 polarity (raw 0 = ON), bits 1-7 raw x,
///             bits 8-14 raw y, bit 15 sync / external input event;
///   bytes 2-3: bits 0-13 timestamp (1 us ticks), bit 14 (byte 3 bit 6)
///             timestamp reset, bit 15 (byte 3 bit 7) timestamp wrap.
inline constexpr int kWordBytes = 4;
inline constexpr std::uint8_t kWrapFlag = 0x80;   ///< in byte 3
inline constexpr std::uint8_t kResetFlag = 0x40;  ///< in byte 3
inline constexpr std::uint16_t kSyncFlag = 0x8000;  ///< in the address
inline constexpr std::int64_t kWrapStep_us = 0x4000;  ///< 16.384 ms per wrap word
inline constexpr std::uint16_t kTimestampMask = 0x3FFF;

}  // namespace evlife::io::dvs128
