// Where an output may go: never onto the file being read (the writer would
// truncate the input before the reader reaches its end); into folders that
// are created when missing, by every command alike (`-o results/run1/x.h5`).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <system_error>

namespace evlife::io {

/// True when two outputs name one file: through links (a link whose target
/// does not exist yet too), "." and "..", whether or not the file exists.
inline bool outputs_name_one_file(const std::string& a, const std::string& b) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::equivalent(a, b, ec)) return true;
  const auto resolved = [](fs::path p) {
    std::error_code e;
    for (int hops = 0; hops < 40 && fs::is_symlink(p, e); ++hops) {  // 40: the kernel's limit
      const fs::path target = fs::read_symlink(p, e);
      if (e) break;
      p = target.is_absolute() ? target : p.parent_path() / target;
    }
    p = fs::absolute(p, e);  // (weakly_canonical leaves a relative path of no existing part relative)
    const fs::path canonical = fs::weakly_canonical(p, e);
    return e ? p.lexically_normal() : canonical;
  };
  return resolved(a) == resolved(b);
}

/// The refusal when `output` names the same file as an existing `input`
/// (through any link, also through folders the output's path creates:
/// "new/../in.csv", which equivalent() cannot compare before `new` exists);
/// nothing otherwise.
inline std::optional<std::string> output_overwrites_input(const std::string& input, const std::string& output) {
  std::error_code ec;
  if (!std::filesystem::exists(input, ec) || !outputs_name_one_file(input, output)) return std::nullopt;
  return output + " is the input file; refusing to overwrite it";
}

/// The refusal of an output that exists and is not a regular file (a folder,
/// a FIFO, a device) for a writer that must seek within its file (`why`:
/// "a video's container is completed by seeking back into it"); nothing
/// otherwise. (A FIFO would also make the open wait for a reader.)
inline std::optional<std::string> seekable_output_problem(const std::string& output, const std::string& why) {
  std::error_code ec;
  const auto status = std::filesystem::status(output, ec);
  if (ec || !std::filesystem::exists(status) || std::filesystem::is_regular_file(status)) return std::nullopt;
  return "not a regular file (a folder, a pipe or a device): " + why + "; write it to a file";
}

/// Creates the folders above `output` that do not exist yet. Returns why
/// that failed ("cannot create the folder a/b: Permission denied"), for the
/// open of the file itself to say instead of its own "No such file or
/// directory"; empty on success.
inline std::string create_output_folders(const std::string& output) {
  std::error_code ec;
  const std::filesystem::path parent = std::filesystem::path(output).parent_path();
  if (parent.empty() || std::filesystem::create_directories(parent, ec) || !ec) return {};
  return "cannot create the folder " + parent.string() + ": " + ec.message();
}

}  // namespace evlife::io
