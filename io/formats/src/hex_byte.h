// A byte as "0x" and two hex digits, for messages naming a record's op code
// (MCAP opcodes, ROS 1 bag ops).
#pragma once

#include <cstdint>
#include <string>

namespace evlife::io::detail {

inline std::string hex_byte(std::uint8_t byte) {
  constexpr char kDigits[] = "0123456789abcdef";
  return std::string("0x") + kDigits[byte >> 4] + kDigits[byte & 15];
}

}  // namespace evlife::io::detail
