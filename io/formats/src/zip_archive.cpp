#include "zip_archive.h"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <optional>
#include <span>

#include "evlife/io/event_reader.h"

namespace evlife::io::detail {
namespace {

constexpr std::uint32_t kEndOfDirectory = 0x06054b50;
constexpr std::uint32_t kZip64EndLocator = 0x07064b50;
constexpr std::uint32_t kZip64End = 0x06064b50;
constexpr std::uint32_t kDirectoryEntry = 0x02014b50;
constexpr std::uint32_t kLocalHeader = 0x04034b50;
constexpr std::uint32_t kDataDescriptor = 0x08074b50;
constexpr std::size_t kEndBytes = 22;
constexpr std::size_t kMaxCommentBytes = 0xFFFF;
constexpr std::size_t kEntryBytes = 46;
constexpr std::size_t kLocalBytes = 30;
/// np.savez archives list a handful of arrays: a directory beyond this is not one.
constexpr std::uint64_t kMaxDirectoryBytes = 64ULL << 20;
/// Sizes beyond this are corrupt (and would overflow signed offsets).
constexpr std::uint64_t kMaxMemberBytes = 1ULL << 62;
/// A cut archive's local headers are followed up to this many members.
constexpr std::size_t kMaxScannedMembers = 1U << 16;

std::uint64_t le(const std::uint8_t* p, int bytes) {
  std::uint64_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

[[noreturn]] void fail(const InputFile& file, std::uint64_t offset, const std::string& why) {
  throw ReadError(file.path(), static_cast<std::int64_t>(offset), -1, "not a readable ZIP archive: " + why);
}

std::vector<std::uint8_t> read_exact(const InputFile& file, std::uint64_t offset, std::size_t bytes, const char* what) {
  std::vector<std::uint8_t> out(bytes);
  if (offset > file.size_bytes() || file.read_at(offset, std::as_writable_bytes(std::span(out))) != bytes)
    fail(file, offset, std::string("the file ends inside ") + what);
  return out;
}

/// Where the end of central directory record begins (it may be followed by
/// a comment of up to 64 KiB); none in a cut archive.
std::optional<std::uint64_t> find_end_record(const InputFile& file) {
  const std::uint64_t size = file.size_bytes();
  if (size < kEndBytes) return std::nullopt;
  const std::uint64_t tail_bytes = std::min<std::uint64_t>(size, kEndBytes + kMaxCommentBytes);
  const std::uint64_t tail_at = size - tail_bytes;
  const std::vector<std::uint8_t> tail = read_exact(file, tail_at, static_cast<std::size_t>(tail_bytes), "its end");
  for (std::size_t i = tail.size() - kEndBytes + 1; i-- > 0;) {
    // Its comment within the file (bytes after it, as some tools append, are allowed: zipfile reads them).
    if (le(&tail[i], 4) == kEndOfDirectory && i + kEndBytes + le(&tail[i + 20], 2) <= tail.size())
      return tail_at + i;
  }
  return std::nullopt;
}

/// A ZIP64 extended-information extra field: the 64-bit values of the fields
/// whose 32-bit ones are 0xFFFFFFFF, in APPNOTE's order.
void apply_zip64_extra(std::span<const std::uint8_t> extra, ZipMember& m, bool& size_big, bool& compressed_big,
                       bool& offset_big) {
  for (std::size_t at = 0; at + 4 <= extra.size();) {
    const auto id = le(&extra[at], 2);
    const auto len = static_cast<std::size_t>(le(&extra[at + 2], 2));
    if (at + 4 + len > extra.size()) return;
    if (id == 0x0001) {
      std::size_t p = at + 4;
      const auto take = [&](bool& big, std::uint64_t& value) {
        if (!big || p + 8 > at + 4 + len) return;
        value = le(&extra[p], 8);
        p += 8;
        big = false;
      };
      take(size_big, m.size_bytes);
      take(compressed_big, m.compressed_bytes);
      take(offset_big, m.local_header_offset);
    }
    at += 4 + len;
  }
}

/// Bounds a cursor to the member's size, and checks its CRC-32 at finish().
class MemberCursor final : public Cursor {
 public:
  MemberCursor(std::unique_ptr<Cursor> inner, const ZipMember& member, std::uint64_t data_at)
      : inner_(std::move(inner)), left_(member.size_bytes), expected_crc_(member.crc32),
        cut_message_(member.cut ? "the archive is cut: it ends at byte " + std::to_string(data_at + member.compressed_bytes) +
                                      ", inside this member"
                                : std::string{}) {}
  std::size_t read(std::span<std::byte> out) override {
    const auto want = static_cast<std::size_t>(std::min<std::uint64_t>(out.size(), left_));
    const std::size_t got = inner_->read(out.first(want));
    crc_ = crc32_z(crc_, reinterpret_cast<const Bytef*>(out.data()), got);
    left_ -= got;
    if (got < out.size() && error_.empty()) {
      if (got < want) {
        error_ = !cut_message_.empty()       ? cut_message_
                 : inner_->error().empty() ? "the member's data ends early"
                                           : inner_->error();
      } else {
        end_short("the member ends");
      }
    }
    return got;
  }
  bool finish() override {
    if (!error_.empty() && !ended_short_) return false;
    error_.clear();
    ended_short_ = false;
    if (left_ != 0) {
      error_ = "the member was not read to its end";
      return false;
    }
    if (!inner_->finish()) {
      error_ = inner_->error();
      return false;
    }
    if (crc_ != expected_crc_) {
      error_ = "its CRC-32 does not match (corrupt data)";
      return false;
    }
    return true;
  }

 private:
  std::unique_ptr<Cursor> inner_;
  std::uint64_t left_;
  std::uint32_t expected_crc_;
  std::string cut_message_;  ///< why the data ends early, for a cut member
  std::uint32_t crc_ = 0;
};

/// The member's data offset, from its local header (whose name and extra
/// lengths may differ from the central directory's).
std::uint64_t data_offset(const InputFile& file, const ZipMember& m) {
  const std::vector<std::uint8_t> local = read_exact(file, m.local_header_offset, kLocalBytes, "a local header");
  if (le(local.data(), 4) != kLocalHeader) fail(file, m.local_header_offset, "member '" + m.name + "': no local header");
  return m.local_header_offset + kLocalBytes + le(&local[26], 2) + le(&local[28], 2);
}

/// Whether a ZIP record's signature ("PK" and two bytes) is at `at`.
bool signature_at(const InputFile& file, std::uint64_t at) {
  std::array<std::uint8_t, 2> pk{};
  return file.read_at(at, std::as_writable_bytes(std::span(pk))) == 2 && pk[0] == 'P' && pk[1] == 'K';
}

/// A member written to a stream (flag bit 3: zipfile on a pipe) states its
/// sizes in a data descriptor after its data: signature 0x08074b50, CRC-32,
/// then the compressed and uncompressed sizes (8 bytes each in ZIP64, else 4).
/// Found as the first signature from `data_at` whose compressed size is its
/// distance from `data_at` (data that happens to hold the signature does not
/// also hold that distance); nullopt before the file ends.
struct DataDescriptor {
  std::uint32_t crc32 = 0;
  std::uint64_t compressed_bytes = 0, size_bytes = 0, bytes = 0;
};
std::optional<DataDescriptor> find_data_descriptor(const InputFile& file, std::uint64_t data_at) {
  constexpr std::size_t kBlock = 1 << 16, kLongest = 24;
  std::vector<std::uint8_t> block(kBlock + kLongest);
  for (std::uint64_t at = data_at; at < file.size_bytes(); at += kBlock) {
    const std::size_t got = file.read_at(at, std::as_writable_bytes(std::span(block)));
    for (std::size_t i = 0; i + 16 <= got && i < kBlock; ++i) {
      if (block[i] != 'P' || le(&block[i], 4) != kDataDescriptor) continue;
      const std::uint64_t distance = at + i - data_at;
      if (i + 24 <= got && le(&block[i + 8], 8) == distance)
        return DataDescriptor{static_cast<std::uint32_t>(le(&block[i + 4], 4)), distance, le(&block[i + 16], 8), 24};
      if (le(&block[i + 8], 4) == distance)
        return DataDescriptor{static_cast<std::uint32_t>(le(&block[i + 4], 4)), distance, le(&block[i + 12], 4), 16};
    }
    if (got <= kBlock) break;  // the file's end
  }
  return std::nullopt;
}

/// Without an end record: the members as their local headers show them,
/// from the start of the file, until a header that is not one (the central
/// directory, or the cut) or a member that runs past the file's end or whose
/// size its header does not state (zipfile writes 0 until the member is
/// closed; a data descriptor follows the data and cannot be found): that one
/// is read to the cut.
ZipDirectory scan_local_headers(const InputFile& file) {
  const std::uint64_t size = file.size_bytes();
  ZipDirectory d;
  std::uint64_t at = 0, header_bytes = 0;
  std::string ended;  // what ends the scan, for the note
  for (;;) {
    std::array<std::uint8_t, kLocalBytes> h{};
    const std::size_t got = at <= size ? file.read_at(at, std::as_writable_bytes(std::span(h))) : 0;
    if (got < 4 || le(h.data(), 4) != kLocalHeader) {
      ended = got == 0                                ? "its end"
              : le(h.data(), 4) == kDirectoryEntry ? "its central directory"
                                                     : "what is not a local header";
      break;
    }
    const auto name_bytes = static_cast<std::size_t>(le(&h[26], 2));
    const auto extra_bytes = static_cast<std::size_t>(le(&h[28], 2));
    header_bytes += name_bytes + extra_bytes;
    if (got < kLocalBytes || kLocalBytes + name_bytes + extra_bytes > size - at) {
      ended = "a cut local header";
      break;
    }
    if (d.members.size() == kMaxScannedMembers || header_bytes > kMaxDirectoryBytes) {
      ended = "the " + std::to_string(d.members.size()) + " members followed";
      break;
    }
    ZipMember m;
    m.flags = static_cast<std::uint16_t>(le(&h[6], 2));
    m.method = static_cast<std::uint16_t>(le(&h[8], 2));
    m.crc32 = static_cast<std::uint32_t>(le(&h[14], 4));
    m.compressed_bytes = le(&h[18], 4);
    m.size_bytes = le(&h[22], 4);
    m.local_header_offset = at;
    std::vector<std::uint8_t> name_extra =
        read_exact(file, at + kLocalBytes, name_bytes + extra_bytes, "a local header");
    m.name.assign(reinterpret_cast<const char*>(name_extra.data()), name_bytes);
    bool size_big = m.size_bytes == 0xFFFFFFFF, compressed_big = m.compressed_bytes == 0xFFFFFFFF, offset_big = false;
    apply_zip64_extra(std::span(name_extra).subspan(name_bytes), m, size_big, compressed_big, offset_big);
    const std::uint64_t data_at = at + kLocalBytes + name_bytes + extra_bytes;
    std::uint64_t descriptor_bytes = 0;
    if ((m.flags & 0x8) != 0) {  // its sizes after its data, in a data descriptor
      if (const auto found = find_data_descriptor(file, data_at);
          found && found->compressed_bytes <= kMaxMemberBytes && found->size_bytes <= kMaxMemberBytes) {
        m.crc32 = found->crc32;
        m.compressed_bytes = found->compressed_bytes;
        m.size_bytes = found->size_bytes;
        size_big = compressed_big = false;
        descriptor_bytes = found->bytes;
      }
    }
    const bool unstated = size_big || compressed_big || ((m.flags & 0x8) != 0 && descriptor_bytes == 0) ||
                          m.compressed_bytes > kMaxMemberBytes || m.size_bytes > kMaxMemberBytes ||
                          (m.compressed_bytes == 0 && data_at < size && !signature_at(file, data_at));
    if (unstated || m.compressed_bytes > size - data_at) {  // read to the cut
      m.cut = true;
      m.size_unstated = unstated;
      m.compressed_bytes = size - data_at;
      if (unstated) m.size_bytes = m.method == 0 ? m.compressed_bytes : kMaxMemberBytes;
      d.members.push_back(std::move(m));
      ended = "the cut";
      at = size;
      break;
    }
    d.members.push_back(std::move(m));
    at = data_at + d.members.back().compressed_bytes + descriptor_bytes;
  }
  if (d.members.empty())
    fail(file, at, "no end of central directory record, and no member from its start (" + ended + ")");
  d.cut_at = at;
  const std::string found = std::to_string(d.members.size()) + (d.members.size() == 1 ? " member" : " members");
  d.cut_note = ended == "its central directory"
                   ? "no end of central directory record (the archive is cut inside its central directory, which "
                     "begins at byte " + std::to_string(at) + "): its " + found + " found by their local headers"
                   : "no end of central directory record (a cut archive?): " + found +
                         " found by their local headers, up to " + ended + " at byte " + std::to_string(at) +
                         "; any after it are lost";
  return d;
}

}  // namespace

ZipDirectory read_zip_directory(const InputFile& file) {
  const std::optional<std::uint64_t> end_record = find_end_record(file);
  if (!end_record) return scan_local_headers(file);
  const std::uint64_t end_at = *end_record;
  const std::vector<std::uint8_t> end = read_exact(file, end_at, kEndBytes, "its end record");
  std::uint64_t entries = le(&end[10], 2);
  std::uint64_t directory_bytes = le(&end[12], 4);
  std::uint64_t directory_at = le(&end[16], 4);
  if (entries == 0xFFFF || directory_bytes == 0xFFFFFFFF || directory_at == 0xFFFFFFFF) {
    // ZIP64: a locator just before the end record names the ZIP64 end record.
    if (end_at < 20) fail(file, end_at, "ZIP64 values without a ZIP64 locator");
    const std::vector<std::uint8_t> locator = read_exact(file, end_at - 20, 20, "its ZIP64 locator");
    if (le(locator.data(), 4) != kZip64EndLocator) fail(file, end_at - 20, "ZIP64 values without a ZIP64 locator");
    const std::uint64_t zip64_at = le(&locator[8], 8);
    const std::vector<std::uint8_t> z = read_exact(file, zip64_at, 56, "its ZIP64 end record");
    if (le(z.data(), 4) != kZip64End) fail(file, zip64_at, "no ZIP64 end record where its locator says");
    entries = le(&z[32], 8);
    directory_bytes = le(&z[40], 8);
    directory_at = le(&z[48], 8);
  }
  if (directory_bytes > kMaxDirectoryBytes || directory_at > file.size_bytes() ||
      directory_bytes > file.size_bytes() - directory_at)
    fail(file, end_at, "its central directory lies outside the file");
  const std::vector<std::uint8_t> dir =
      read_exact(file, directory_at, static_cast<std::size_t>(directory_bytes), "its central directory");
  ZipDirectory d;
  std::vector<ZipMember>& members = d.members;
  std::size_t at = 0;
  for (std::uint64_t k = 0; k < entries; ++k) {
    const std::uint64_t offset = directory_at + at;
    if (at + kEntryBytes > dir.size() || le(&dir[at], 4) != kDirectoryEntry)
      fail(file, offset, "central directory entry " + std::to_string(k) + " is cut or not one");
    ZipMember m;
    m.flags = static_cast<std::uint16_t>(le(&dir[at + 8], 2));
    m.method = static_cast<std::uint16_t>(le(&dir[at + 10], 2));
    m.crc32 = static_cast<std::uint32_t>(le(&dir[at + 16], 4));
    m.compressed_bytes = le(&dir[at + 20], 4);
    m.size_bytes = le(&dir[at + 24], 4);
    const auto name_bytes = static_cast<std::size_t>(le(&dir[at + 28], 2));
    const auto extra_bytes = static_cast<std::size_t>(le(&dir[at + 30], 2));
    const auto comment_bytes = static_cast<std::size_t>(le(&dir[at + 32], 2));
    m.local_header_offset = le(&dir[at + 42], 4);
    if (at + kEntryBytes + name_bytes + extra_bytes + comment_bytes > dir.size())
      fail(file, offset, "central directory entry " + std::to_string(k) + " is cut");
    m.name.assign(reinterpret_cast<const char*>(&dir[at + kEntryBytes]), name_bytes);
    bool size_big = m.size_bytes == 0xFFFFFFFF, compressed_big = m.compressed_bytes == 0xFFFFFFFF,
         offset_big = m.local_header_offset == 0xFFFFFFFF;
    apply_zip64_extra(std::span(dir).subspan(at + kEntryBytes + name_bytes, extra_bytes), m, size_big, compressed_big,
                      offset_big);
    if (size_big || compressed_big || offset_big)
      fail(file, offset, "member '" + m.name + "': 32-bit sizes without their ZIP64 values");
    if (m.size_bytes > kMaxMemberBytes || m.compressed_bytes > kMaxMemberBytes)
      fail(file, offset, "member '" + m.name + "' states a size beyond 2^62 bytes");
    members.push_back(std::move(m));
    at += kEntryBytes + name_bytes + extra_bytes + comment_bytes;
  }
  return d;
}

std::int64_t zip_member_data_offset(const InputFile& file, const ZipMember& member) {
  return member.method == 0 ? static_cast<std::int64_t>(data_offset(file, member)) : -1;
}

std::unique_ptr<Cursor> open_zip_member(const InputFile& file, const ZipMember& member) {
  if ((member.flags & 0x1) != 0) fail(file, member.local_header_offset, "member '" + member.name + "' is encrypted");
  const std::uint64_t at = data_offset(file, member);
  if (at > file.size_bytes() || member.compressed_bytes > file.size_bytes() - at)
    fail(file, at, "member '" + member.name + "' ends beyond the file (cut?)");
  std::unique_ptr<Cursor> inner;
  if (member.method == 0) {
    if (member.compressed_bytes != member.size_bytes && !member.cut)
      fail(file, member.local_header_offset, "stored member '" + member.name + "' states two sizes");
    inner = std::make_unique<RawCursor>(file, at, at + member.size_bytes);
  } else if (member.method == 8) {
    inner = std::make_unique<InflateCursor>(file, at, at + member.compressed_bytes, InflateCursor::Wrapping::raw);
  } else {
    fail(file, member.local_header_offset,
         "member '" + member.name + "' uses compression method " + std::to_string(member.method) +
             " (stored and deflated members are read: np.savez, np.savez_compressed)");
  }
  return std::make_unique<MemberCursor>(std::move(inner), member, at);
}

}  // namespace evlife::io::detail
