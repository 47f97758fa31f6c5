// Private: the members of a ZIP archive (PKWARE's APPNOTE: end of central
// directory, ZIP64 end records, central directory, local headers), as
// np.savez and np.savez_compressed write them: stored or deflated members,
// ZIP64 sizes. No Debian C++ library reads ZIP members as streams without
// extracting them (libzip reads them, but is no dependency here); this is
// the small decoder the .npz reader needs, fuzzed (fuzz_npz).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "byte_cursor.h"
#include "input_file.h"

namespace evlife::io::detail {

struct ZipMember {
  std::string name;
  std::uint16_t method = 0;  ///< 0 stored, 8 deflated (others are refused when opened)
  std::uint16_t flags = 0;
  std::uint32_t crc32 = 0;
  std::uint64_t compressed_bytes = 0;
  std::uint64_t size_bytes = 0;         ///< uncompressed
  std::uint64_t local_header_offset = 0;
  /// The archive ends inside its data (found by its local header, or its size
  /// unknown there): read up to the file's end, where a cursor's read stops
  /// with an error saying so.
  bool cut = false;
  /// Its local header states no size (zipfile's placeholder, a data
  /// descriptor): its data may end before the cut, its size is a bound.
  bool size_unstated = false;
};

struct ZipDirectory {
  std::vector<ZipMember> members;
  /// Empty, or why the members were found by their local headers: an archive
  /// without its end record, cut while written or copied. What its members
  /// hold up to the cut is readable; the members after it are lost.
  std::string cut_note;
  std::uint64_t cut_at = 0;  ///< the file offset the note is about
};

/// The archive's members, in central-directory order; without an end of
/// central directory record (a cut archive), those its local headers show
/// from the start of the file (cut_note says so). Throws ReadError naming the
/// file and the byte offset of what is wrong (a directory outside the file, a
/// cut entry, no member found).
ZipDirectory read_zip_directory(const InputFile& file);

/// A cursor over a member's uncompressed bytes: they end at its stated size,
/// and finish() checks its CRC-32 (over every byte read: read them all
/// first). Throws ReadError (encrypted, an unknown compression method, a local
/// header that is not one) naming the member.
std::unique_ptr<Cursor> open_zip_member(const InputFile& file, const ZipMember& member);

/// The file offset of a stored member's first data byte (-1 when compressed).
std::int64_t zip_member_data_offset(const InputFile& file, const ZipMember& member);

}  // namespace evlife::io::detail
