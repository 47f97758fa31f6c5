// NumPy .npy files (np.save), as Python users keep events: one array, read by
// npy_events.h (a structured array with fields x, y, t, p, or N x 4 columns).
#include <cstring>
#include <memory>

#include "byte_cursor.h"
#include "npy_events.h"
#include "reader_registry.h"

namespace evlife::io::detail {
namespace {

SniffResult sniff_npy(std::span<const std::byte> head, std::string_view path) {
  if (head.size() >= kNpyMagicBytes && std::memcmp(head.data(), kNpyMagic, kNpyMagicBytes) == 0)
    return SniffResult::by_content;
  return has_extension(path, ".npy") ? SniffResult::by_extension : SniffResult::no;
}

std::unique_ptr<EventReader> open_npy(const std::string& path, const ReaderOptions& options) {
  NpyArray array;
  array.file = std::make_shared<const InputFile>(path);
  const std::uint64_t size = array.file->size_bytes();
  array.bytes = std::make_unique<RawCursor>(*array.file, 0, size);
  array.header = read_npy_header(*array.bytes, path, "");
  array.file_offset = array.header.data_offset;
  array.available_bytes = static_cast<std::int64_t>(size) - array.header.data_offset;
  std::vector<NpyArray> arrays;
  arrays.push_back(std::move(array));
  return make_npy_event_reader(path, "npy", std::move(arrays), NpyLayout::one_array, options);
}

}  // namespace

const ReaderFormat npy_format{
    "npy",
    "NumPy .npy (np.save): fields x, y, t, p of a structured array, or N x 4 columns; t in µs or float s "
    "(else --time-unit)",
    &sniff_npy, nullptr, &open_npy, nullptr, "time-unit"};

}  // namespace evlife::io::detail
