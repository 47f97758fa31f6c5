// Private: events from NumPy arrays, for the .npy and .npz readers:
//  - one array: a structured array whose fields are named x, y,
//    t|ts|time|timestamp (optionally with a unit: t_us, timestamp_ns) and
//    p|pol|polarity, of any integer, bool, float or datetime64 type (other
//    fields ignored), or an N x 4 array of one numeric type in a layout the
//    CSV reader reads (x,y,p,t, x,y,t,p or t,x,y,p), told from its first rows
//    the same way (column_layout.h);
//  - four 1-D arrays, one per column (an .npz of np.savez(x=, y=, t=, p=)).
// Time unit: ReaderOptions::time_unit (--time-unit), else the name's, else
// datetime64's, else seconds where a float time column holds fractions
// among its first rows, else µs. Polarity 1 = ON, 0 or -1 = OFF.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "byte_cursor.h"
#include "evlife/io/event_reader.h"
#include "npy_header.h"

namespace evlife::io::detail {

/// One array's records: its bytes after the header, and where they are.
struct NpyArray {
  std::string name;               ///< for messages: "" (the file), or the archive member's name
  NpyHeader header;
  std::shared_ptr<const InputFile> file;  ///< what `bytes` reads (declared first: outlives it)
  std::unique_ptr<Cursor> bytes;  ///< positioned at the first record
  std::int64_t available_bytes = 0;  ///< the data bytes the file or member holds after the header
  bool size_unknown = false;  ///< available_bytes is a bound (a cut archive's member of unstated size)
  std::int64_t file_offset = -1;  ///< of the first record in the file; -1 when compressed
};

/// Which array holds which column. One array: the whole event (structured or
/// N x 4); four: x, y, t, p in that order, each 1-D.
enum class NpyLayout { one_array, column_arrays };

/// The reader; throws ReadError naming `path` when the arrays are not events
/// (the reason, and what is readable).
/// `streams`: an archive's arrays, for `evlife info` (EventReader::streams()).
/// `fault_after_events`: thrown after the last event where the arrays hold no
/// fault of their own (a cut archive whose arrays read are whole).
std::unique_ptr<EventReader> make_npy_event_reader(std::string path, std::string_view format,
                                                   std::vector<NpyArray> arrays, NpyLayout layout,
                                                   const ReaderOptions& options,
                                                   std::vector<ContainerStream> streams = {},
                                                   std::optional<ReadError> fault_after_events = std::nullopt);

/// Whether a header is one array of events (structured with the four names,
/// or 2-D with 4 columns), or a 1-D array of numbers (one column).
bool holds_events(const NpyHeader& h);
bool holds_a_column(const NpyHeader& h);

/// Reads an array's header from `bytes` (then positioned at its first
/// record); `where` names it in messages. Throws ReadError naming `path`.
NpyHeader read_npy_header(Cursor& bytes, const std::string& path, const std::string& where);

/// An archive member's array name as np.load gives it: "x" for "x.npy".
std::string npy_array_name(const std::string& member);

/// What is readable, for messages.
std::string npy_layouts();

}  // namespace evlife::io::detail
