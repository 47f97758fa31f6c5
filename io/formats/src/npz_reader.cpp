// NumPy .npz archives (np.savez, np.savez_compressed: a ZIP of .npy arrays,
// stored or deflated), read as they stream (zip_archive.h), never extracted:
//  - the one array that holds events (npy_events.h: structured with fields
//    x, y, t, p, or N x 4), e.g. np.savez(f, events=a); or
//  - four 1-D arrays named as the columns, np.savez(f, x=x, y=y, t=t, p=p)
//    (the names of the CSV header and the structured fields: xs, ts,
//    polarity, t_us...), of equal length.
// --topic NAME chooses an array of events among several. Arrays of other
// names (labels, images) are passed over.
#include <algorithm>
#include <array>
#include <cctype>
#include <cstring>
#include <memory>

#include "column_layout.h"
#include "npy_events.h"
#include "reader_registry.h"
#include "zip_archive.h"

namespace evlife::io::detail {
namespace {

/// np.savez archives hold a few arrays; each is opened to read its header.
constexpr std::size_t kMaxArrays = 4096;

std::string base_name(const std::string& member) {
  return member.ends_with(".npy") ? member.substr(0, member.size() - 4) : member;
}

struct Listed {
  const ZipMember* member;
  NpyHeader header;
};

std::string listing(const std::vector<Listed>& arrays) {
  std::string text;
  for (const Listed& a : arrays) text += (text.empty() ? "" : ", ") + base_name(a.member->name) + " " + npy_shape_text(a.header);
  return text.empty() ? "none" : text;
}

/// The chosen member's array, its cursor at the first record.
NpyArray open_array(const std::shared_ptr<const InputFile>& file, const ZipMember& m, const std::string& path) {
  NpyArray a;
  a.name = m.name;
  a.file = file;
  a.bytes = open_zip_member(*file, m);
  a.header = read_npy_header(*a.bytes, path, "array '" + m.name + "'");
  a.available_bytes = static_cast<std::int64_t>(m.size_bytes) - a.header.data_offset;
  const std::int64_t data_at = zip_member_data_offset(*file, m);
  a.file_offset = data_at < 0 ? -1 : data_at + a.header.data_offset;
  return a;
}

std::unique_ptr<EventReader> open_npz(const std::string& path, const ReaderOptions& options) {
  auto file = std::make_shared<const InputFile>(path);
  const std::vector<ZipMember> members = read_zip_directory(*file);
  std::vector<Listed> arrays;
  for (const ZipMember& m : members) {
    if (!m.name.ends_with(".npy")) continue;  // np.savez writes NAME.npy only
    if (arrays.size() == kMaxArrays)
      throw ReadError(path, -1, -1, "more than " + std::to_string(kMaxArrays) + " arrays: not an archive of events");
    const std::unique_ptr<Cursor> bytes = open_zip_member(*file, m);
    arrays.push_back(Listed{&m, read_npy_header(*bytes, path, "array '" + m.name + "'")});
  }
  const auto refuse = [&](const std::string& why) -> std::unique_ptr<EventReader> {
    throw ReadError(path, -1, -1,
                    "not readable events: " + why + " (arrays: " + listing(arrays) + "); " + kNpyLayouts +
                        ", or 1-D arrays named x, y, t and p");
  };
  const auto one = [&](const Listed& a) {
    std::vector<NpyArray> chosen;
    chosen.push_back(open_array(file, *a.member, path));
    return make_npy_event_reader(path, "npz", std::move(chosen), NpyLayout::one_array, options);
  };
  if (!options.topic.empty()) {
    for (const Listed& a : arrays) {
      if (a.member->name == options.topic || base_name(a.member->name) == options.topic) {
        if (!holds_events(a.header)) return refuse("--topic " + options.topic + " is not an array of events");
        return one(a);
      }
    }
    return refuse("--topic " + options.topic + ": no such array");
  }
  std::vector<const Listed*> events;
  std::array<const Listed*, 4> columns{};
  for (const Listed& a : arrays) {
    if (holds_events(a.header)) events.push_back(&a);
    std::int64_t unit = 0;
    const int role = holds_a_column(a.header) ? column_role(lower_ascii(base_name(a.member->name)), unit) : -1;
    if (role < 0) continue;
    if (columns[static_cast<std::size_t>(role)] != nullptr) {
      return refuse("arrays '" + base_name(columns[static_cast<std::size_t>(role)]->member->name) + "' and '" +
                    base_name(a.member->name) + "' both name " + std::string(1, "xytp"[role]));
    }
    columns[static_cast<std::size_t>(role)] = &a;
  }
  const bool all_columns = std::find(columns.begin(), columns.end(), nullptr) == columns.end();
  if (events.size() == 1 && !all_columns) return one(*events.front());
  if (events.empty() && all_columns) {
    std::vector<NpyArray> chosen;
    for (const Listed* c : columns) chosen.push_back(open_array(file, *c->member, path));
    return make_npy_event_reader(path, "npz", std::move(chosen), NpyLayout::column_arrays, options);
  }
  if (events.empty()) return refuse("no array of events");
  return refuse("several arrays of events; --topic NAME chooses one");
}

SniffResult sniff_npz(std::span<const std::byte> head, std::string_view path) {
  // A ZIP's first local header whose name ends in .npy: what np.savez writes first.
  if (head.size() >= 30 && std::memcmp(head.data(), "PK\x03\x04", 4) == 0) {
    const auto u16 = [&head](std::size_t at) {
      return static_cast<std::size_t>(static_cast<unsigned char>(head[at])) |
             static_cast<std::size_t>(static_cast<unsigned char>(head[at + 1])) << 8;
    };
    const std::size_t name_bytes = u16(26);
    if (30 + name_bytes <= head.size()) {
      const std::string_view name(reinterpret_cast<const char*>(head.data()) + 30, name_bytes);
      if (name.ends_with(".npy")) return SniffResult::by_content;
    }
  }
  return has_extension(path, ".npz") ? SniffResult::by_extension : SniffResult::no;
}

}  // namespace

const ReaderFormat npz_format{
    "npz",
    "NumPy .npz (np.savez, np.savez_compressed): its array of events (as .npy), or 1-D arrays x, y, t, p; "
    "--topic NAME chooses among several",
    &sniff_npz, nullptr, &open_npz, nullptr, "topic, time-unit"};

}  // namespace evlife::io::detail
