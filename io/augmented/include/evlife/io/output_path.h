// Where an output may go: never onto the file being read (the writer would
// truncate the input before the reader reaches its end).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <system_error>

namespace evlife::io {

/// The refusal when `output` names the same file as `input` (through any
/// link); nothing otherwise (also when either does not exist yet).
inline std::optional<std::string> output_overwrites_input(const std::string& input, const std::string& output) {
  std::error_code ec;
  if (!std::filesystem::equivalent(input, output, ec)) return std::nullopt;
  return output + " is the input file; refusing to overwrite it";
}

}  // namespace evlife::io
