#include "rosbag2_messages.h"

#include <sqlite3.h>
#include <yaml-cpp/yaml.h>
#include <zstd.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <string_view>

#include "evlife/io/event_reader.h"
#include "input_file.h"
#include "ros_topics.h"
#include "zstd_temp_copy.h"

namespace evlife::io::ros {
namespace {

namespace fs = std::filesystem;

// A decompressed message larger than this is taken for a corrupt frame (an
// event message of a camera at 20 M events/s over 1 s is under 200 MiB).
constexpr unsigned long long kMaxInflatedMessageBytes = 256ULL << 20;

/// A .db3 of a file-compressed bag: rosbag2's compressor names it NAME.db3.zstd.
bool is_compressed_db3_name(const fs::path& p) {
  return p.extension() == ".zstd" && p.stem().extension() == ".db3";
}

/// File names in the order rosbag2 splits them: digit runs compare as
/// numbers (bag_2 before bag_10; as strings bag_10 came first and the bag's
/// time went backwards at its third file).
bool split_file_order_less(const std::string& a, const std::string& b) {
  const auto digit = [](char c) { return c >= '0' && c <= '9'; };
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (digit(a[i]) && digit(b[j])) {
      std::size_t ei = i, ej = j;
      while (ei < a.size() && digit(a[ei])) ++ei;
      while (ej < b.size() && digit(b[ej])) ++ej;
      std::size_t zi = i, zj = j;  // leading zeros do not make a number larger
      while (zi + 1 < ei && a[zi] == '0') ++zi;
      while (zj + 1 < ej && b[zj] == '0') ++zj;
      if (ei - zi != ej - zj) return ei - zi < ej - zj;
      if (const int c = a.compare(zi, ei - zi, b, zj, ej - zj); c != 0) return c < 0;
      i = ei, j = ej;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i, ++j;
    }
  }
  if (a.size() - i != b.size() - j) return a.size() - i < b.size() - j;
  return a < b;  // equal as numbers (bag_01, bag_1): any fixed order
}

struct BagMetadata {
  int version = 0;  // 0: not stated
  std::string storage, compression_format, compression_mode;
  std::vector<std::string> files;  // relative_file_paths, as listed
  bool has_file_list = false;      // the key is there (maybe with no file)
  std::map<std::string, std::uint64_t> message_counts;  // topics_with_message_count, by topic name
};

/// topics_with_message_count's entries (topic_metadata: {name}, message_count);
/// an entry without both is passed over: the counts only check the files.
std::map<std::string, std::uint64_t> topic_message_counts(const YAML::Node& list) {
  // (A missing key gives an invalid node: only IsDefined() may be asked of it.)
  std::map<std::string, std::uint64_t> counts;
  if (!list.IsDefined() || !list.IsSequence()) return counts;
  for (const YAML::Node& entry : list) {
    if (!entry.IsMap()) continue;
    const YAML::Node topic = entry["topic_metadata"];
    const YAML::Node count = entry["message_count"];
    if (!topic.IsDefined() || !count.IsDefined() || !topic.IsMap() || !count.IsScalar()) continue;
    const YAML::Node name = topic["name"];
    if (!name.IsDefined() || !name.IsScalar()) continue;
    const std::string& digits = count.Scalar();
    std::uint64_t value = 0;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (ec != std::errc{} || end != digits.data() + digits.size()) continue;  // not a whole count
    std::uint64_t& sum = counts[name.Scalar()];  // (a topic listed twice: both counts, saturating)
    sum += std::min(value, std::numeric_limits<std::uint64_t>::max() - sum);
  }
  return counts;
}

/// metadata.yaml's keys evlife uses, under rosbag2_bagfile_information (or
/// at the top, where another writer left that key out). Parsed as YAML
/// (yaml-cpp): block or flow lists, over one line or several, quoted or not.
BagMetadata read_bag_metadata(const std::string& path) {
  YAML::Node loaded;
  try {
    loaded = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw ReadError(path, -1, -1,
                    "not YAML (line " + std::to_string(e.mark.line + 1) + ", column " + std::to_string(e.mark.column + 1) +
                        ": " + e.msg + "): a damaged rosbag2 metadata file (the bag's files cannot be told; without "
                        "metadata.yaml its .db3 files are read)");
  }
  BagMetadata m;
  const YAML::Node& root = loaded;  // const: a look-up never adds a key
  if (!root.IsMap()) return m;      // empty, or a text: no key
  // (A missing key gives an invalid node: only IsDefined() may be asked of it.)
  const YAML::Node wrapped = root["rosbag2_bagfile_information"];
  const YAML::Node info = wrapped.IsDefined() && wrapped.IsMap() ? wrapped : root;
  const auto text = [&](const char* key) -> std::string {
    const YAML::Node v = info[key];
    if (!v.IsDefined() || v.IsNull()) return {};
    if (!v.IsScalar()) throw ReadError(path, -1, -1, std::string(key) + " is not a single value");
    return v.Scalar();
  };
  m.storage = text("storage_identifier");
  m.compression_format = text("compression_format");
  m.compression_mode = text("compression_mode");
  m.version = std::atoi(text("version").c_str());
  m.message_counts = topic_message_counts(info["topics_with_message_count"]);
  const YAML::Node files = info["relative_file_paths"];
  m.has_file_list = files.IsDefined();
  if (!m.has_file_list) return m;
  if (files.IsSequence()) {
    for (const YAML::Node& f : files) {
      if (!f.IsScalar()) throw ReadError(path, -1, -1, "relative_file_paths holds an entry that is not a file name");
      if (!f.Scalar().empty()) m.files.push_back(f.Scalar());
    }
  } else if (files.IsScalar() && !files.Scalar().empty()) {  // one name, not a list
    m.files.push_back(files.Scalar());
  }
  return m;
}

/// The .db3 files of a bag folder, in reading order; `m` gets its
/// metadata.yaml's (none: left as it is).
std::vector<std::string> bag_folder_files(const std::string& dir, BagMetadata& m) {
  std::vector<std::string> files;
  const fs::path metadata = fs::path(dir) / "metadata.yaml";
  if (std::ifstream in(metadata); in) {
    m = read_bag_metadata(metadata.string());
    const std::string &storage = m.storage, &compression_format = m.compression_format,
                      &compression_mode = m.compression_mode;
    // Up to version 3 rosbag2 wrote the paths with the bag folder's name in
    // front (relative to the folder's parent), as its reader resolves them.
    // ("bag/", "." and "./" name the folder too: its parent is that of the absolute path).
    std::error_code cwd_error;  // no working directory: the path as given
    fs::path folder = fs::absolute(dir, cwd_error).lexically_normal();
    if (!folder.has_filename()) folder = folder.parent_path();
    const fs::path base = m.version >= 1 && m.version <= 3 ? folder.parent_path() : fs::path(dir);
    for (const std::string& f : m.files) files.push_back((base / f).string());
    // zstd by message (each message a frame) or by file (NAME.db3.zstd): both read.
    if (!compression_format.empty() && compression_mode != "NONE" && compression_mode != "none" &&
        !compression_mode.empty() && compression_format != "zstd") {
      throw ReadError(metadata.string(), -1, -1,
                      "a rosbag2 bag compressed with " + compression_format + " (compression_mode " + compression_mode +
                          "): evlife reads uncompressed bags and zstd compression; write an uncompressed "
                          "copy with `ros2 bag convert`");
    }
    if (storage == "mcap") {  // the default storage since ROS 2 Iron: read by the MCAP reader
      std::string names;
      for (const std::string& f : files) names += (names.empty() ? "" : ", ") + f;
      throw ReadError(metadata.string(), -1, -1,
                      "a rosbag2 bag in MCAP storage: give its .mcap file" +
                          std::string(files.size() > 1 ? "s one at a time" : "") + " (" +
                          (names.empty() ? "none listed" : names) + ")");
    }
    if (!storage.empty() && storage != "sqlite3") {
      throw ReadError(metadata.string(), -1, -1,
                      "rosbag2 storage '" + storage + "' is not readable (sqlite3 .db3 bags, and .mcap files)");
    }
    if (files.empty()) {  // what is wrong: a file that is no rosbag2 metadata, or an empty list
      throw ReadError(metadata.string(), -1, -1,
                      m.has_file_list ? "rosbag2 metadata lists no file under relative_file_paths"
                                   : "no relative_file_paths key: not rosbag2 metadata, or a damaged file (the bag's "
                                     "files cannot be told; without metadata.yaml its .db3 files are read)");
    }
    return files;
  }
  // No metadata.yaml: a recording that did not stop cleanly (rosbag2 writes it
  // at the end); with file compression its closed files are NAME.db3.zstd.
  // Both NAME.db3 and NAME.db3.zstd: stopped while compressing it (rosbag2
  // removes the .db3 once its .zstd is whole), so the .db3 is the one to read.
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const fs::path& p = entry.path();
    if (p.extension() == ".db3" || (is_compressed_db3_name(p) && !fs::exists(p.parent_path() / p.stem(), ec)))
      files.push_back(p.string());
  }
  std::sort(files.begin(), files.end(), split_file_order_less);
  if (files.empty()) throw ReadError(dir, -1, -1, "folder without metadata.yaml or .db3 files");
  return files;
}

}  // namespace

bool is_rosbag2_directory(const std::string& path) {
  std::error_code ec;
  if (!fs::is_directory(path, ec)) return false;
  if (fs::exists(fs::path(path) / "metadata.yaml", ec)) return true;
  for (const auto& entry : fs::directory_iterator(path, ec)) {
    if (entry.path().extension() == ".db3" || is_compressed_db3_name(entry.path())) return true;
  }
  return false;
}

bool is_zstd_stream(std::span<const std::byte> head) {
  return head.size() >= 4 && head[0] == std::byte{0x28} && head[1] == std::byte{0xB5} && head[2] == std::byte{0x2F} &&
         head[3] == std::byte{0xFD};
}

namespace {

/// A database file shorter than its header states: SQLite reads the pages it
/// lacks as zeros, without an error (PRAGMA integrity_check passes), so a bag
/// cut inside its last page gave zeroed messages. `open_path` is the file
/// SQLite opens, `shown_path` the user's (a .db3.zstd's).
void check_not_cut(const std::string& open_path, const std::string& shown_path) {
  const detail::InputFile file(open_path);
  std::array<std::byte, 100> h{};
  if (file.read_at(0, h) < h.size()) return;  // SQLite's open says what it is
  const auto be = [&h](std::size_t at, std::size_t bytes) {
    std::uint32_t v = 0;
    for (std::size_t i = 0; i < bytes; ++i) v = (v << 8) | std::to_integer<std::uint32_t>(h[at + i]);
    return v;
  };
  if (std::memcmp(h.data(), "SQLite format 3", 16) != 0) return;
  // WAL mode (rosbag2's default in Foxy, its "resilient" preset since): a
  // checkpoint cut short leaves the header's count above the file while the
  // -wal file beside it holds the pages, which SQLite reads whole.
  std::error_code ec;
  if (std::filesystem::file_size(open_path + "-wal", ec) > 0 && !ec) return;
  const std::uint32_t page_bytes = be(16, 2) == 1 ? 65536 : be(16, 2);
  const std::uint32_t pages = be(28, 4);
  // The header's page count holds only while its change counter (offset 24)
  // equals its version-valid-for number (offset 92): SQLite's file format, 1.3.
  if (pages == 0 || be(24, 4) != be(92, 4)) return;
  const std::uint64_t stated = std::uint64_t{page_bytes} * pages;
  if (file.size_bytes() >= stated) return;
  const bool copy = open_path != shown_path;
  throw ReadError(shown_path, copy ? -1 : static_cast<std::int64_t>(file.size_bytes()), -1,
                  std::string("cut: the database") + (copy ? " (decompressed)" : "") + " has " +
                      std::to_string(file.size_bytes()) + " bytes where its header states " + std::to_string(pages) +
                      " pages of " + std::to_string(page_bytes) + " bytes (" + std::to_string(stated) + ")");
}

}  // namespace

struct Rosbag2Messages::Db {
  std::string path;  // as the user named it (a .db3.zstd's, not its decompressed copy's)
  sqlite3* db = nullptr;
  sqlite3_stmt* stmt = nullptr;

  Db(const std::string& open_path, std::string shown_path) : path(std::move(shown_path)) {
    check_not_cut(open_path, path);
    if (sqlite3_open_v2(open_path.c_str(), &db, SQLITE_OPEN_READONLY | SQLITE_OPEN_NOMUTEX, nullptr) !=
        SQLITE_OK) {
      const std::string why = db != nullptr ? sqlite3_errmsg(db) : "out of memory";
      sqlite3_close(db);
      throw ReadError(path, -1, -1, "cannot open as an SQLite database: " + why);
    }
  }
  ~Db() {
    sqlite3_finalize(stmt);
    sqlite3_close(db);
  }
  Db(const Db&) = delete;
  Db& operator=(const Db&) = delete;

  [[noreturn]] void fail(const std::string& what) const {
    throw ReadError(path, -1, -1, what + ": " + sqlite3_errmsg(db));
  }
  void prepare(const char* sql) {
    sqlite3_finalize(stmt);
    stmt = nullptr;
    if (sqlite3_prepare_v2(db, sql, -1, &stmt, nullptr) != SQLITE_OK)
      fail("not a rosbag2 sqlite3 bag (query failed)");
  }
  /// sqlite3_step with errors turned into ReadError; true while a row is there.
  bool step(const std::string& what) {
    const int rc = sqlite3_step(stmt);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    fail(what);
  }
  std::string text(int column) const {
    const unsigned char* t = sqlite3_column_text(stmt, column);
    return t != nullptr ? reinterpret_cast<const char*>(t) : "";
  }
};

Rosbag2Messages::Rosbag2Messages(const std::string& path) {
  std::error_code ec;
  BagMetadata metadata;
  files_ = fs::is_directory(path, ec) ? bag_folder_files(path, metadata) : std::vector<std::string>{path};
  metadata_counts_ = std::move(metadata.message_counts);
  std::map<std::string, std::size_t> by_name;
  for (std::size_t i = 0; i < files_.size(); ++i) {
    try {
      read_topics(i, by_name);
    } catch (const ReadError& fault) {
      if (i == 0) throw;
      // A later file of a split bag: the files before it are read, then the fault.
      fault_.emplace(fault);
      files_.resize(i);
      break;
    }
  }
}

void Rosbag2Messages::read_topics(std::size_t i, std::map<std::string, std::size_t>& by_name) {
  const std::string& file = files_[i];
  // One copy at a time: a lone file's is kept for select(); a split bag's
  // are made again when their messages are read.
  const auto copy = copy_of(i);
  if (files_.size() == 1) copy_ = copy;
  {
    Db db(copy ? copy->path() : file, file);
    db.prepare(
        "SELECT t.name, t.type, t.serialization_format, "
        "(SELECT COUNT(*) FROM messages m WHERE m.topic_id = t.id) FROM topics t ORDER BY t.id");
    while (db.step("cannot read the topics table")) {
      add_topic(topics_, by_name,
                TopicInfo{db.text(0), db.text(1), db.text(2), static_cast<std::uint64_t>(sqlite3_column_int64(db.stmt, 3)), {}});
    }
    // NOT EXISTS, not NOT IN: a topics row whose id reads NULL (a damaged schema) made NOT IN false for every message.
    db.prepare("SELECT COUNT(*) FROM messages m WHERE NOT EXISTS (SELECT 1 FROM topics t WHERE t.id = m.topic_id)");
    if (db.step("cannot count the messages of no topic"))
      unlisted_messages_ += static_cast<std::uint64_t>(sqlite3_column_int64(db.stmt, 0));
  }
}

std::shared_ptr<const detail::ZstdTempCopy> Rosbag2Messages::copy_of(std::size_t i) const {
  // By content: a .db3.zstd piped in (evlife's copy of standard input) has no name to go by.
  std::array<std::byte, 4> magic{};
  const std::size_t got = detail::InputFile(files_[i]).read_at(0, magic);
  return is_zstd_stream(std::span(magic.data(), got)) ? detail::ZstdTempCopy::of(files_[i]) : nullptr;
}

Rosbag2Messages::~Rosbag2Messages() = default;

void Rosbag2Messages::open_file(std::size_t i) {
  file_index_ = i;
  db_.reset();
  if (i != 0 || !copy_) {  // (a lone file's copy is kept from the constructor)
    copy_.reset();  // the previous file's, before the next one's is made
    copy_ = copy_of(i);
  }
  db_ = std::make_unique<Db>(copy_ ? copy_->path() : files_[i], files_[i]);
  db_->prepare(
      "SELECT m.data, m.timestamp FROM messages m JOIN topics t ON m.topic_id = t.id "
      "WHERE t.name = ?1 ORDER BY m.timestamp, m.id");
  if (sqlite3_bind_text(db_->stmt, 1, topic_.c_str(), -1, SQLITE_TRANSIENT) != SQLITE_OK)
    db_->fail("cannot select the topic");
}

void Rosbag2Messages::select(const std::string& name) {
  topic_ = name;
  next_index_ = 0;
  selected_ = true;
  // metadata.yaml counts what rosbag2 was given to write: rows lost from a
  // .db3 (a damaged or salvaged database), a file missing from its list, or
  // messages a recorder's full cache dropped (counted before the cache by
  // rosbag2 up to Humble) leave the files fewer. No error (a recording with
  // drops is whole), but counted and shown; messages of no listed topic may
  // be the same ones, and are shown as such.
  const auto counted = metadata_counts_.find(name);
  const auto held = std::find_if(topics_.begin(), topics_.end(), [&](const TopicInfo& t) { return t.name == name; });
  missing_messages_ = 0;
  if (!fault_ && counted != metadata_counts_.end() && held != topics_.end() && held->message_count < counted->second) {
    const std::uint64_t shortfall = counted->second - held->message_count;
    missing_messages_ = shortfall - std::min(shortfall, unlisted_messages_);
  }
  open_file(0);
}

bool Rosbag2Messages::next(Message& m) {
  if (!selected_) return false;
  while (true) {
    if (db_ && db_->step("cannot read message " + std::to_string(next_index_))) break;
    if (file_index_ + 1 >= files_.size()) {
      db_.reset();
      if (fault_) {
        const ReadError fault = *fault_;
        fault_.reset();
        throw fault;
      }
      return false;
    }
    open_file(file_index_ + 1);
  }
  const void* blob = sqlite3_column_blob(db_->stmt, 0);
  const int size = sqlite3_column_bytes(db_->stmt, 0);
  m.data = std::span<const std::uint8_t>(static_cast<const std::uint8_t*>(blob),
                                         static_cast<std::size_t>(std::max(size, 0)));
  m.bag_time_ns = sqlite3_column_int64(db_->stmt, 1);
  m.index = next_index_++;
  m.file = &files_[file_index_];
  if (is_zstd_stream(std::as_bytes(m.data))) m.data = inflate(m.data);  // a CDR message starts 00 01
  return true;
}

std::span<const std::uint8_t> Rosbag2Messages::inflate(std::span<const std::uint8_t> frame) {
  const auto fault = [&](const std::string& what) {
    return ReadError(files_[file_index_], -1, -1,
                     "message " + std::to_string(next_index_ - 1) + " of topic '" + topic_ + "': " + what);
  };
  const unsigned long long size = ZSTD_getFrameContentSize(frame.data(), frame.size());
  if (size == ZSTD_CONTENTSIZE_ERROR || size == ZSTD_CONTENTSIZE_UNKNOWN || size > kMaxInflatedMessageBytes)
    throw fault("a zstd frame that states no size, or more than 256 MiB (corrupt?)");
  inflated_.resize(static_cast<std::size_t>(size));
  const std::size_t got = ZSTD_decompress(inflated_.data(), inflated_.size(), frame.data(), frame.size());
  if (ZSTD_isError(got) != 0U || got != size)
    throw fault(std::string("corrupt zstd-compressed message (") +
                (ZSTD_isError(got) != 0U ? ZSTD_getErrorName(got) : "shorter than it states") + ")");
  return {inflated_.data(), inflated_.size()};
}

}  // namespace evlife::io::ros
