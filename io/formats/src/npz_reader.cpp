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
#include <optional>
#include <string_view>
#include <unordered_map>

#include "column_layout.h"
#include "npy_events.h"
#include "reader_registry.h"
#include "zip_archive.h"

namespace evlife::io::detail {
namespace {

/// np.savez archives hold a few arrays; without --topic each is opened to
/// read its header, up to this many, and this many header bytes in all.
constexpr std::size_t kMaxArrays = 4096;
constexpr std::uint64_t kMaxHeaderBytesInAll = 64ULL << 20;

/// What an archive's array is, kept small (a header's fields are not).
struct Listed {
  const ZipMember* member = nullptr;
  std::string text;           ///< "name (200,)", or "name (not read: why)"
  bool events = false;        ///< holds events by itself
  bool structured = false;    ///< ... as a structured array (named fields), not N x 4
  int role = -1;              ///< a 1-D column's role by its name
  std::int64_t length = 0;    ///< a column's values
  std::string kind;           ///< for `evlife info`: "events", "column t", "other", "not read"
};

/// The arrays as `evlife info` lists them, the ones read marked.
std::vector<ContainerStream> streams_of(const std::vector<Listed>& arrays, const std::vector<const ZipMember*>& read) {
  std::vector<ContainerStream> streams;
  for (const Listed& a : arrays) {
    const bool is_read = std::find(read.begin(), read.end(), a.member) != read.end();
    streams.push_back(ContainerStream{npy_array_name(a.member->name), a.kind, static_cast<std::uint64_t>(a.length), is_read});
  }
  return streams;
}

std::string listing(const std::vector<Listed>& arrays) {
  constexpr std::size_t kListed = 20;  // a message, not a catalogue
  std::string text;
  for (std::size_t i = 0; i < arrays.size() && i < kListed; ++i) text += (text.empty() ? "" : ", ") + arrays[i].text;
  if (arrays.size() > kListed) text += " and " + std::to_string(arrays.size() - kListed) + " more";
  return text.empty() ? "none" : text;
}

/// The chosen member's array, its cursor at the first record.
NpyArray open_array(const std::shared_ptr<const InputFile>& file, const ZipMember& m, const std::string& path) {
  NpyArray a;
  a.name = m.name;
  a.file = file;
  a.bytes = open_zip_member(*file, m);
  a.header = read_npy_header(*a.bytes, path, "array '" + m.name + "'");
  if (static_cast<std::int64_t>(m.size_bytes) < a.header.data_offset)
    throw ReadError(path, -1, -1, "array '" + m.name + "': its stated size is less than its header");
  a.available_bytes = static_cast<std::int64_t>(m.size_bytes) - a.header.data_offset;
  a.size_unknown = m.size_unstated;
  const std::int64_t data_at = zip_member_data_offset(*file, m);
  a.file_offset = data_at < 0 ? -1 : data_at + a.header.data_offset;
  return a;
}

/// The members np.load sees: the .npy ones, the last of several of one name.
std::vector<const ZipMember*> arrays_of(const std::vector<ZipMember>& members) {
  std::unordered_map<std::string_view, std::size_t> last;  // name -> index of its last member
  for (std::size_t i = 0; i < members.size(); ++i)
    if (members[i].name.ends_with(".npy")) last[members[i].name] = i;  // np.savez writes NAME.npy only
  std::vector<const ZipMember*> arrays;
  for (std::size_t i = 0; i < members.size(); ++i) {
    const auto found = last.find(members[i].name);
    if (found != last.end() && found->second == i) arrays.push_back(&members[i]);
  }
  return arrays;
}

/// Reads an array's header to list it; an array that cannot be read (Python
/// objects, an encrypted or bzip2 member) is listed as such and passed over.
Listed list_array(const InputFile& file, const ZipMember& m, const std::string& path, std::uint64_t& header_bytes) {
  Listed a;
  a.member = &m;
  try {
    const std::unique_ptr<Cursor> bytes = open_zip_member(file, m);
    const NpyHeader h = read_npy_header(*bytes, path, "array '" + m.name + "'");
    header_bytes += static_cast<std::uint64_t>(h.data_offset);
    a.text = npy_array_name(m.name) + " " + npy_shape_text(h);
    a.events = holds_events(h);
    a.structured = a.events && !h.fields.empty();
    std::int64_t unit = 0;
    a.role = holds_a_column(h) ? column_role(lower_ascii(npy_array_name(m.name)), unit) : -1;
    a.length = h.shape.empty() ? 0 : h.shape[0];
    a.kind = a.events ? std::string(a.structured ? "events " : "N x 4 ") + npy_shape_text(h)
             : a.role >= 0 ? std::string("column ") + "xytp"[a.role] + " " + npy_shape_text(h)
                           : "other " + npy_shape_text(h);
  } catch (const ReadError& e) {
    a.text = npy_array_name(m.name) + " (not read: " + e.reason() + ")";
    a.kind = "not read";
    // What reading a header may have inflated, charged to the budget too.
    header_bytes += std::min<std::uint64_t>(m.size_bytes, kNpyMaxHeaderBytes + 12);
  }
  return a;
}

std::unique_ptr<EventReader> open_npz(const std::string& path, const ReaderOptions& options) {
  auto file = std::make_shared<const InputFile>(path);
  const ZipDirectory directory = read_zip_directory(*file);
  const std::vector<const ZipMember*> names = arrays_of(directory.members);
  // A cut archive: what its arrays hold up to the cut is read, then this error (the arrays after it are lost).
  std::optional<ReadError> cut;
  if (!directory.cut_note.empty()) cut.emplace(path, static_cast<std::int64_t>(directory.cut_at), -1, directory.cut_note);
  const auto with_cut = [&](const std::string& why) { return cut ? why + "; " + directory.cut_note : why; };
  std::vector<Listed> arrays;
  const auto one = [&](const ZipMember& m) {
    std::vector<NpyArray> chosen;
    chosen.push_back(open_array(file, m, path));
    if (!holds_events(chosen.front().header))
      throw ReadError(path, -1, -1, "--topic " + options.topic + " is not an array of events (" +
                                        npy_shape_text(chosen.front().header) + "); " + npy_layouts());
    for (Listed& a : arrays) {  // the one opened, listed as such
      if (a.member != &m) continue;
      const NpyHeader& h = chosen.front().header;
      a.kind = std::string(h.fields.empty() ? "N x 4 " : "events ") + npy_shape_text(h);
      a.length = h.shape.empty() ? 0 : h.shape[0];
    }
    return make_npy_event_reader(path, "npz", std::move(chosen), NpyLayout::one_array, options,
                                 streams_of(arrays, {&m}), cut);
  };
  if (!options.topic.empty()) {  // only that array is opened; the others are listed by name
    for (std::size_t i = 0; i < names.size() && i < kMaxArrays; ++i) {
      Listed a;
      a.member = names[i];
      a.kind = "(not opened: --topic)";
      arrays.push_back(std::move(a));
    }
    for (const ZipMember* m : names)
      if (m->name == options.topic || npy_array_name(m->name) == options.topic) return one(*m);
    std::string known;
    for (const ZipMember* m : names) known += (known.empty() ? "" : ", ") + npy_array_name(m->name);
    throw ReadError(path, -1, -1, with_cut("--topic " + options.topic + ": no such array (arrays: " +
                                               (known.empty() ? "none" : known) + ")"));
  }
  if (names.size() > kMaxArrays)
    throw ReadError(path, -1, -1, std::to_string(names.size()) + " arrays, more than the " +
                                      std::to_string(kMaxArrays) + " looked through: --topic NAME names the one to read");
  std::uint64_t header_bytes = 0;
  for (const ZipMember* m : names) {
    arrays.push_back(list_array(*file, *m, path, header_bytes));
    if (header_bytes > kMaxHeaderBytesInAll)
      throw ReadError(path, -1, -1, "its arrays' headers exceed " + std::to_string(kMaxHeaderBytesInAll >> 20) +
                                        " MiB in all: --topic NAME names the one to read");
  }
  const auto refuse = [&](const std::string& why) -> std::unique_ptr<EventReader> {
    throw ReadError(path, -1, -1,
                    with_cut("not readable events: " + why + " (arrays: " + listing(arrays) + "); " + npy_layouts() +
                             ", or 1-D arrays named x, y, t and p"));
  };
  // A structured array of events first (named fields say it is events); several: the user chooses.
  const auto events_of = [&arrays](bool structured) {
    std::vector<const Listed*> found;
    for (const Listed& a : arrays)
      if (a.events && a.structured == structured) found.push_back(&a);
    return found;
  };
  if (const auto named = events_of(true); !named.empty()) {
    if (named.size() > 1) return refuse("several arrays of events; --topic NAME chooses one");
    return one(*named.front()->member);
  }
  // Then one 1-D array per column, named as the columns, of one length (arrays of other lengths,
  // e.g. frame times, pass over); an unnamed N x 4 array (bounding boxes?) only without them.
  std::array<std::vector<const Listed*>, 4> by_role;
  for (const Listed& a : arrays)
    if (a.role >= 0) by_role[static_cast<std::size_t>(a.role)].push_back(&a);
  std::vector<std::int64_t> lengths;
  for (const Listed* a : by_role[kX]) lengths.push_back(a->length);
  for (const std::int64_t length : lengths) {
    std::array<const Listed*, 4> chosen{};
    bool unique = true;
    for (std::size_t role = 0; role < 4 && unique; ++role) {
      for (const Listed* a : by_role[role]) {
        if (a->length != length) continue;
        unique = chosen[role] == nullptr;
        if (!unique) {
          return refuse("arrays '" + npy_array_name(chosen[role]->member->name) + "' and '" + npy_array_name(a->member->name) +
                        "' both name " + std::string(1, "xytp"[role]));
        }
        chosen[role] = a;
      }
    }
    if (std::find(chosen.begin(), chosen.end(), nullptr) != chosen.end()) continue;
    std::vector<NpyArray> columns;
    std::vector<const ZipMember*> read;
    for (const Listed* c : chosen) {
      columns.push_back(open_array(file, *c->member, path));
      read.push_back(c->member);
    }
    return make_npy_event_reader(path, "npz", std::move(columns), NpyLayout::column_arrays, options,
                                 streams_of(arrays, read), cut);
  }
  if (const auto plain = events_of(false); !plain.empty()) {
    if (plain.size() > 1) return refuse("several N x 4 arrays; --topic NAME chooses one");
    return one(*plain.front()->member);
  }
  const bool some_columns = std::any_of(by_role.begin(), by_role.end(), [](const auto& v) { return !v.empty(); });
  return refuse(some_columns ? "no array of events, and no x, y, t and p arrays of one length" : "no array of events");
}

SniffResult sniff_npz(std::span<const std::byte> head, std::string_view path) {
  // A ZIP's first local header whose name ends in .npy: what np.savez writes first. Another
  // ZIP is this reader's too, weakly (no other reads ZIP): it says what the archive holds.
  const bool zip = head.size() >= 4 && std::memcmp(head.data(), "PK\x03\x04", 4) == 0;
  if (zip && head.size() >= 30) {
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
  return zip || has_extension(path, ".npz") ? SniffResult::by_extension : SniffResult::no;
}

}  // namespace

const ReaderFormat npz_format{
    "npz",
    "NumPy .npz (np.savez, np.savez_compressed): its array of events (as .npy), or 1-D arrays x, y, t, p; "
    "--topic NAME chooses among several",
    &sniff_npz, nullptr, &open_npz, nullptr, "topic, time-unit"};

}  // namespace evlife::io::detail
