#include "hdf5_reader.h"

#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>
#include <type_traits>

#include "hdf5_attributes.h"
#include "hdf5_error_silencer.h"
#include "hdf5_lzf_filter.h"
#include "column_layout.h"  // the time units
#include "hdf5_open_probe.h"
#include "hdf5_read_child.h"
#include "hdf5_signature.h"
#include "reader_registry.h"

namespace evlife::io {
namespace {

static_assert(std::is_same_v<hid_t, std::int64_t>, "Hdf5Reader::Hid must be hid_t");


// True if every component of `path` ("a/b/c") exists as a link in `file`.
bool exists(hid_t file, const std::string& path) {
  for (std::size_t slash = path.find('/'); ; slash = path.find('/', slash + 1)) {
    const std::string prefix = path.substr(0, slash);
    if (H5Lexists(file, prefix.c_str(), H5P_DEFAULT) <= 0) return false;
    if (slash == std::string::npos) return true;
  }
}

// True if `path` names a dataset (not a group) in `file`.
bool is_dataset(hid_t file, const std::string& path) {
  H5O_info_t info{};
  return exists(file, path) &&
         H5Oget_info_by_name2(file, path.c_str(), &info, H5O_INFO_BASIC, H5P_DEFAULT) >= 0 &&
         info.type == H5O_TYPE_DATASET;
}

// Length of the 1-D dataset `dataset`; -1 if it is not 1-D.
std::int64_t length_1d(hid_t dataset) {
  const hid_t space = H5Dget_space(dataset);
  if (space < 0) return -1;
  std::int64_t length = -1;
  hsize_t dims[1] = {0};
  if (H5Sget_simple_extent_ndims(space) == 1 && H5Sget_simple_extent_dims(space, dims, nullptr) == 1) {
    length = static_cast<std::int64_t>(dims[0]);
  }
  H5Sclose(space);
  return length;
}

// A filter of `dataset`'s pipeline that this HDF5 cannot load, said with where
// to get it; nullopt when every filter is there. Chunks stored without it (an
// optional filter that did not shrink them, as h5py's LZF) still read, so it
// is said when a read fails, not at opening.
std::optional<std::string> missing_filter(hid_t dataset) {
  const hid_t properties = H5Dget_create_plist(dataset);
  if (properties < 0) return std::nullopt;
  std::optional<std::string> missing;
  const int filters = H5Pget_nfilters(properties);
  for (int i = 0; i < filters && !missing; ++i) {
    unsigned flags = 0, filter_config = 0;
    std::size_t values = 0;
    char name[96] = {};
    const H5Z_filter_t id = H5Pget_filter2(properties, static_cast<unsigned>(i), &flags, &values, nullptr,
                                           sizeof name, name, &filter_config);
    if (id < 0 || H5Zfilter_avail(id) > 0) continue;
    // Debian 12's packages of the filters event datasets use (DSEC: Blosc).
    const char* package = id == 32001                ? "hdf5-filter-plugin-blosc-serial"
                          : id == 307 || id == 32004 ? "hdf5-filter-plugin"
                          : id == 32013              ? "hdf5-filter-plugin-zfp-serial"
                                                     : nullptr;
    missing = "compressed with HDF5 filter " + std::to_string(id) + (name[0] != '\0' ? " ('" + std::string(name) + "')" : "") +
              ", which this HDF5 cannot load: " +
              (package != nullptr ? "install Debian's " + std::string(package) + ", or put the filter's plugin on HDF5_PLUGIN_PATH"
                                  : std::string("put the filter's plugin on HDF5_PLUGIN_PATH"));
  }
  H5Pclose(properties);
  return missing;
}

using detail::kHdf5MaxChunkBytes;

// LZF parameters that do not state the dataset's chunk size `bytes` (a corrupt
// file): its decoder could not tell a short chunk from a whole one.
std::optional<std::string> lzf_chunk_size_mismatch(hid_t dataset, std::uint64_t bytes) {
  const hid_t properties = H5Dget_create_plist(dataset);
  if (properties < 0) return std::nullopt;
  unsigned flags = 0;
  std::size_t count = 3;
  unsigned values[3] = {};
  std::optional<std::string> mismatch;
  if (H5Pget_filter_by_id2(properties, detail::kHdf5LzfFilterId, &flags, &count, values, 0, nullptr, nullptr) >= 0) {
    const std::uint64_t stated = count >= 3 ? values[2] : 0;
    if (stated != bytes) {
      mismatch = "its LZF filter states chunks of " + std::to_string(stated) + " bytes, its chunks hold " +
                 std::to_string(bytes) + " (corrupt?)";
    }
  }
  H5Pclose(properties);
  return mismatch;
}

/// libhdf5's chunk cache per dataset, and the most a dataset is given instead.
constexpr std::uint64_t kDefaultChunkCacheBytes = std::uint64_t{1} << 20;
constexpr std::uint64_t kMaxChunkCacheBytes = std::uint64_t{64} << 20;

// Bytes of one storage chunk of `dataset` (0 when it is not chunked).
std::uint64_t chunk_bytes(hid_t dataset) {
  const hid_t properties = H5Dget_create_plist(dataset);
  if (properties < 0) return 0;
  std::uint64_t bytes = 0;
  if (H5Pget_layout(properties) == H5D_CHUNKED) {
    hsize_t dims[H5S_MAX_RANK] = {};
    const int rank = H5Pget_chunk(properties, H5S_MAX_RANK, dims);
    const hid_t type = H5Dget_type(dataset);
    bytes = type >= 0 ? H5Tget_size(type) : 0;
    if (type >= 0) H5Tclose(type);
    for (int i = 0; i < rank; ++i) {
      bytes = dims[i] != 0 && bytes > kHdf5MaxChunkBytes / dims[i] ? kHdf5MaxChunkBytes + 1 : bytes * dims[i];
    }
    if (rank < 0) bytes = kHdf5MaxChunkBytes + 1;  // unreadable chunk description: corrupt
  }
  H5Pclose(properties);
  return bytes;
}

// Whether a chunk of `dataset` is longer than a dimension that cannot grow:
// HDF5 refuses to create one (but for an empty dimension), so the file is corrupt, and libhdf5 1.10 reads
// past a shorter decompressed chunk there (found by fuzz_hdf5:
// regressions/hdf5/chunk_beyond_its_fixed_dimension.h5).
bool chunk_beyond_fixed_extent(hid_t dataset) {
  const hid_t properties = H5Dget_create_plist(dataset);
  if (properties < 0) return false;
  hsize_t chunk[H5S_MAX_RANK] = {}, extent[H5S_MAX_RANK] = {}, max_extent[H5S_MAX_RANK] = {};
  const int rank = H5Pget_layout(properties) == H5D_CHUNKED ? H5Pget_chunk(properties, H5S_MAX_RANK, chunk) : 0;
  H5Pclose(properties);
  const hid_t space = H5Dget_space(dataset);
  const int space_rank = space >= 0 ? H5Sget_simple_extent_dims(space, extent, max_extent) : -1;
  if (space >= 0) H5Sclose(space);
  for (int i = 0; i < rank && i < space_rank; ++i) {
    // (An empty dimension, 0, is left alone: HDF5 makes such datasets, and none is read there.)
    if (max_extent[i] != H5S_UNLIMITED && max_extent[i] != 0 && chunk[i] > max_extent[i]) return true;
  }
  return false;
}

// Rows [first, first + count) of a 1-D dataset, or of an N×`columns` one
// (column `column` alone when `column` >= 0, else every column), read by the
// reader's child (hdf5_read_child.h). HDF5 converts a value that the memory
// type cannot hold by clamping (x = -1 read as 0) or truncating (12.7 as 12):
// such a value fails the read instead, and the reader names its row
// (first_unconvertible_row).
bool read_slab(detail::Hdf5ReadChild& reads, hid_t dataset, hid_t memory_type, std::int64_t first, std::size_t count,
               void* out, int columns = 0, int column = -1) {
  const detail::Hdf5Selection selection{first, count, columns, column, false};
  return reads.read(dataset, memory_type, selection, out, detail::selection_bytes(dataset, memory_type, selection));
}

// The dataset `name` of `file` opened, or -1 when there is none (a group,
// nothing, or unreadable): for the optional datasets beside the events.
hid_t open_if_dataset(hid_t file, const std::string& name) {
  return is_dataset(file, name) ? H5Dopen2(file, name.c_str(), H5P_DEFAULT) : hid_t{-1};
}

// The sensor of a stack of grey frames stored beside the events (v2e's
// frame, MVSEC's image_raw: N × height × width), if there is one.
std::optional<SensorSize> sensor_of_frames(hid_t file, const std::string& name) {
  const hid_t dataset = open_if_dataset(file, name);
  if (dataset < 0) return std::nullopt;
  const hid_t space = H5Dget_space(dataset);
  hsize_t dims[3] = {0, 0, 0};
  const bool stack = space >= 0 && H5Sget_simple_extent_ndims(space) == 3 &&
                     H5Sget_simple_extent_dims(space, dims, nullptr) == 3;
  if (space >= 0) H5Sclose(space);
  H5Dclose(dataset);
  if (!stack || dims[1] == 0 || dims[2] == 0 || dims[1] > 65536 || dims[2] > 65536) return std::nullopt;
  return SensorSize{static_cast<int>(dims[2]), static_cast<int>(dims[1])};
}

// A sensor stated as a dataset of two integers [width, height] (M3ED's
// calib/resolution), if there is one.
std::optional<SensorSize> sensor_of_resolution(detail::Hdf5ReadChild& reads, hid_t file, const std::string& name) {
  const hid_t dataset = open_if_dataset(file, name);
  if (dataset < 0) return std::nullopt;
  std::int64_t size[2] = {0, 0};
  const bool ok = length_1d(dataset) == 2 &&
                  reads.read(dataset, H5T_NATIVE_INT64, detail::Hdf5Selection{.whole = true}, size, sizeof size);
  H5Dclose(dataset);
  if (!ok || size[0] <= 0 || size[1] <= 0 || size[0] > 65536 || size[1] > 65536) return std::nullopt;
  return SensorSize{static_cast<int>(size[0]), static_cast<int>(size[1])};
}

// True if `dataset` is N×`columns`; its N in `rows`.
bool is_rows_of(hid_t dataset, int columns, std::int64_t& rows) {
  const hid_t space = H5Dget_space(dataset);
  if (space < 0) return false;
  hsize_t dims[2] = {0, 0};
  const bool table = H5Sget_simple_extent_ndims(space) == 2 &&
                     H5Sget_simple_extent_dims(space, dims, nullptr) == 2 &&
                     dims[1] == static_cast<hsize_t>(columns);
  H5Sclose(space);
  rows = static_cast<std::int64_t>(dims[0]);
  return table;
}

bool is_float(hid_t dataset) {
  const hid_t type = H5Dget_type(dataset);
  if (type < 0) return false;
  const bool result = H5Tget_class(type) == H5T_FLOAT;
  H5Tclose(type);
  return result;
}

// "-1", "12.7", "9.22337203685478e+18": the value as written, not "-1.000000".
std::string shortest_text(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.15g", value);
  return text;
}

// A pixel coordinate held as a double (MVSEC's table): a whole number in
// [0, 65535], else false.
bool to_coordinate(double value, std::uint16_t& out) {
  if (!(value >= 0.0 && value <= 65535.0) || value != std::floor(value)) return false;
  out = static_cast<std::uint16_t>(value);
  return true;
}

// What a column's value must be to be an event's: a pixel coordinate
// (to_coordinate), a time in int64 microseconds (to_microseconds), a polarity
// within int8.
enum class ColumnKind { coordinate, time_us, polarity };

// The first of `count` rows from `first` whose value the column cannot hold
// without change (read as doubles, which hold every such value's size), with
// that value; nothing when every row fits (the read failed for another reason).
std::optional<std::pair<std::size_t, double>> first_unconvertible_row(detail::Hdf5ReadChild& reads, hid_t dataset,
                                                                      ColumnKind kind,
                                                                      std::int64_t first, std::size_t count) {
  std::vector<double> values(count);
  if (!read_slab(reads, dataset, H5T_NATIVE_DOUBLE, first, count, values.data())) return std::nullopt;
  for (std::size_t i = 0; i < count; ++i) {
    const double v = values[i];
    std::uint16_t coordinate = 0;
    std::int64_t t_us = 0;
    const bool fits = kind == ColumnKind::coordinate ? to_coordinate(v, coordinate)
                      : kind == ColumnKind::time_us  ? v == std::floor(v) && detail::float_time_to_us(v, 1000, t_us)
                                                     : v == std::floor(v) && v >= -128.0 && v <= 127.0;
    if (!fits) return std::pair{i, v};
  }
  return std::nullopt;
}

}  // namespace

// The column orders of the N×4 tables.
constexpr Hdf5Reader::TableColumns kMvsecColumns{2, 0, 1, 3};  // rows x, y, t, p
constexpr Hdf5Reader::TableColumns kV2eColumns{0, 1, 2, 3};    // rows t, x, y, p

// The dataset `name` opened for reading, after the checks that keep a corrupt
// file's storage from reaching libhdf5 (chunks larger than any writer makes,
// or longer than the dataset; LZF chunks of the wrong size). Throws
// ReadError naming it, every handle closed (the constructor's callers get no
// destructor).
Hdf5Reader::Hid Hdf5Reader::open_column(const std::string& name) {
  hid_t dataset = H5Dopen2(file_, name.c_str(), H5P_DEFAULT);
  // The file's fault with this dataset (`why` follows its quoted name): nothing of it is read.
  const auto refuse = [&](const std::string& why) {
    if (dataset >= 0) H5Dclose(dataset);
    close_handles();
    throw ReadError(path_, -1, -1, "HDF5 dataset '" + name + "'" + why);
  };
  if (dataset < 0) refuse(" cannot be opened");
  const std::uint64_t bytes = chunk_bytes(dataset);
  if (bytes > kHdf5MaxChunkBytes)
    refuse(" is stored in chunks of more than " + std::to_string(kHdf5MaxChunkBytes >> 20) + " MiB (corrupt?)");
  if (chunk_beyond_fixed_extent(dataset)) refuse(" is stored in chunks longer than the dataset (corrupt)");
  if (const auto mismatch = lzf_chunk_size_mismatch(dataset, bytes)) refuse(": " + *mismatch);
  if (const auto missing = missing_filter(dataset); missing && unloadable_filter_.empty()) {
    unloadable_filter_ = "'" + name + "' is " + *missing;
  }
  if (bytes > kDefaultChunkCacheBytes) {
    // libhdf5 caches 1 MiB of chunks per dataset: each read of kChunkEvents rows of a larger
    // chunk decompressed it again (a 4 MiB chunk 16 times, ~10x the time). Room for two.
    // (Closed first: an open dataset's second handle shares its cache.)
    H5Dclose(dataset);
    const hid_t access = H5Pcreate(H5P_DATASET_ACCESS);
    if (access >= 0) H5Pset_chunk_cache(access, H5D_CHUNK_CACHE_NSLOTS_DEFAULT, std::min(2 * bytes, kMaxChunkCacheBytes), 1.0);
    dataset = H5Dopen2(file_, name.c_str(), access >= 0 ? access : H5P_DEFAULT);
    if (access >= 0) H5Pclose(access);
    if (dataset < 0) refuse(" cannot be opened again");
  }
  return dataset;
}

Hdf5Reader::Hdf5Reader(const std::string& path, const std::string& topic, const std::string& time_unit)
    : path_(path), reads_(std::make_unique<detail::Hdf5ReadChild>()) {
  const Hdf5ErrorSilencer silence;
  detail::register_hdf5_lzf_filter();
  if (H5Fis_hdf5(path.c_str()) <= 0) {
    throw ReadError(path, 0, -1, "not an HDF5 file (or cannot be opened)");
  }
  probe_hdf5_open_in_child(path);  // a libhdf5 crash on a corrupt file becomes a ReadError
  std::error_code size_error;
  file_bytes_ = static_cast<std::int64_t>(std::filesystem::file_size(path, size_error));
  if (size_error) file_bytes_ = 0;
  file_ = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (file_ < 0) throw ReadError(path, -1, -1, hdf5_cannot_open_reason(path));

  std::string prefix;
  const char* names[4] = {"x", "y", "t", "p"};
  if (!topic.empty()) {
    if (is_dataset(file_, topic)) {  // an MVSEC camera's table
      layout_ = "mvsec";
      table_name_ = topic;
      table_ = kMvsecColumns;
    } else if (exists(file_, topic + "/x")) {  // a group of x, y, t, p columns (M3ED's cameras)
      layout_ = topic.rfind("prophesee/", 0) == 0 ? "m3ed" : "columns";
      prefix = topic + "/";
    } else {
      close_handles();
      throw ReadError(path, -1, -1,
                      "HDF5 file has no table and no group of x, y, t, p columns '" + topic +
                          "' (--topic names an MVSEC camera's table, e.g. davis/right/events, or a group "
                          "of columns, e.g. M3ED's prophesee/right)");
    }
  } else if (exists(file_, "events/x")) {
    layout_ = "dsec";
    prefix = "events/";
  } else if (exists(file_, "events/xs")) {
    layout_ = "event_utils";
    prefix = "events/";
    names[0] = "xs", names[1] = "ys", names[2] = "ts", names[3] = "ps";
  } else if (exists(file_, "CD/events")) {
    layout_ = "prophesee";
  } else if (exists(file_, "davis/left/events")) {
    layout_ = "mvsec";
    table_name_ = "davis/left/events";
    table_ = kMvsecColumns;
  } else if (exists(file_, "prophesee/left/x")) {  // M3ED: a group per camera
    layout_ = "m3ed";
    prefix = "prophesee/left/";
  } else if (is_dataset(file_, "events")) {
    layout_ = "v2e";
    table_name_ = "events";
    table_ = kV2eColumns;
  } else if (exists(file_, "x")) {
    layout_ = "evlife";
  } else {
    // A right camera alone (MVSEC, M3ED): say how to read it.
    const char* right = exists(file_, "davis/right/events")  ? "davis/right/events"
                        : exists(file_, "prophesee/right/x") ? "prophesee/right"
                                                             : nullptr;
    close_handles();
    if (right != nullptr) {
      throw ReadError(path, -1, -1,
                      std::string("HDF5 file of a right camera alone: read it with --topic ") + right +
                          " (Python: topic=)");
    }
    throw ReadError(path, -1, -1,
                    "HDF5 file holds no known event layout: found no dataset 'events/x' (DSEC: "
                    "events/{x,y,t,p}), 'events/xs' (event_utils: events/{xs,ys,ts,ps}), "
                    "'CD/events' (Prophesee compound), 'davis/left/events' (MVSEC: N×4 x,y,t,p), "
                    "'prophesee/left/x' (M3ED: prophesee/left/{x,y,t,p}), 'events' (v2e: N×4 t,x,y,p) or "
                    "'x' (evlife: x,y,t,p); --topic names another table or group of columns");
  }

  if (is_table()) {
    t_ = open_column(table_name_);
    if (!is_rows_of(t_, 4, total_)) {
      close_handles();
      throw ReadError(path, -1, -1,
                      "HDF5 " + std::string(layout_) + " layout: dataset '" + table_name_ +
                          "' is not a table of 4 columns (" +
                          (table_.t == 0 ? "t, x, y, p" : "x, y, t, p") + ")");
    }
    t_float_ = is_float(t_);  // (a table is read as doubles either way)
  } else if (layout_ == "prophesee") {
    t_ = open_column("CD/events");
    total_ = length_1d(t_);
    const hid_t type = H5Dget_type(t_);
    const bool compound = type >= 0 && H5Tget_class(type) == H5T_COMPOUND;
    if (type >= 0) H5Tclose(type);
    if (!compound) {
      close_handles();
      throw ReadError(path, -1, -1, "HDF5 dataset 'CD/events' is not a compound of x, y, p, t");
    }
  } else {
    for (const char* column : names) {
      if (!exists(file_, prefix + column)) {
        close_handles();
        throw ReadError(path, -1, -1,
                        "HDF5 " + std::string(layout_) + " layout: dataset '" + prefix + column +
                            "' is missing");
      }
    }
    for (int i = 0; i < 4; ++i) column_names_[i] = prefix + names[i];
    x_ = open_column(column_names_[0]);
    y_ = open_column(column_names_[1]);
    t_ = open_column(column_names_[2]);
    p_ = open_column(column_names_[3]);
    total_ = length_1d(x_);
    for (const auto& [dataset, name] : {std::pair{y_, names[1]}, {t_, names[2]}, {p_, names[3]}}) {
      if (length_1d(dataset) != total_) {
        close_handles();
        throw ReadError(path, -1, -1,
                        "HDF5 dataset '" + prefix + name + "' does not have the length of '" +
                            prefix + names[0] + "' (" + std::to_string(total_) + ")");
      }
    }
    t_float_ = is_float(t_);
    if (layout_ == "dsec" && exists(file_, "t_offset")) {
      const hid_t offset = open_column("t_offset");
      // (Into one int64: a t_offset of more values fails, not overflows it.)
      const bool ok = reads_->read(offset, H5T_NATIVE_INT64, detail::Hdf5Selection{.whole = true}, &t_offset_us_,
                                  sizeof t_offset_us_);
      H5Dclose(offset);
      if (!ok) {
        close_handles();
        throw ReadError(path, -1, -1, "HDF5 dataset 't_offset' is not a scalar integer");
      }
    }
  }
  if (total_ < 0) {
    close_handles();
    throw ReadError(path, -1, -1, "HDF5 event datasets are not one-dimensional");
  }
  choose_time_unit(time_unit);
  const auto width = read_int_attribute(file_, "width");
  const auto height = read_int_attribute(file_, "height");
  if (width && height && *width > 0 && *height > 0 && *width <= 65536 && *height <= 65536) {
    sensor_ = SensorSize{static_cast<int>(*width), static_cast<int>(*height)};
  } else if (layout_ == "v2e") {
    sensor_ = sensor_of_frames(file_, "frame");
  } else if (layout_ == "mvsec") {  // davis/left/events: davis/left/image_raw
    sensor_ = sensor_of_frames(file_, table_name_.substr(0, table_name_.rfind('/') + 1) + "image_raw");
  } else if (layout_ == "m3ed") {  // prophesee/left/calib/resolution: [width, height]
    sensor_ = sensor_of_resolution(*reads_, file_, prefix + "calib/resolution");
  }
  if (layout_ == "prophesee") {
    records_.resize(kChunkEvents);
  } else {
    xs_.resize(kChunkEvents);
    ys_.resize(kChunkEvents);
    ts_.resize(kChunkEvents);
    ps_.resize(kChunkEvents);
    if (is_table()) doubles_.resize(4 * kChunkEvents);
    else if (t_float_) doubles_.resize(kChunkEvents);
  }
}

Hdf5Reader::~Hdf5Reader() { close_handles(); }

std::vector<ContainerStream> Hdf5Reader::streams() const {
  std::vector<ContainerStream> cameras;
  if (file_ < 0) return cameras;
  const Hdf5ErrorSilencer silence;
  // A camera whose events are counted in `counted`: its N×4 table (`table`),
  // else its x column; listed if that dataset is one and is read as one.
  const auto add = [&](const std::string& name, const std::string& counted, bool table) {
    const hid_t dataset = open_if_dataset(file_, counted);
    if (dataset < 0) return;
    std::int64_t rows = -1;
    if (!table) rows = length_1d(dataset);
    else if (!is_rows_of(dataset, 4, rows)) rows = -1;
    H5Dclose(dataset);
    if (rows < 0) return;
    cameras.push_back({name, table ? "x, y, t, p" : "x, y, t, p columns", static_cast<std::uint64_t>(rows),
                       counted == (table ? table_name_ : column_names_[0])});
  };
  if (layout_ == "mvsec") {
    for (const char* camera : {"davis/left/events", "davis/right/events"}) add(camera, camera, true);
  } else if (layout_ == "m3ed") {
    for (const std::string camera : {"prophesee/left", "prophesee/right"}) add(camera, camera + "/x", false);
  }
  return cameras;
}

// Why a read failed, in parentheses: libhdf5 crashed or hung in the child
// that read, else a filter this HDF5 cannot load, else `otherwise`.
std::string Hdf5Reader::why_unread(const char* otherwise) const {
  if (const auto& fault = reads_->fault()) {
    return fault->corrupt ? " (the HDF5 library " + fault->verb + " reading it " + fault->detail + ": corrupt HDF5)"
                          : " (its reading process " + fault->verb + " " + fault->detail + ")";
  }
  return unloadable_filter_.empty() ? " (" + std::string(otherwise) + ")" : " (dataset " + unloadable_filter_ + ")";
}

void Hdf5Reader::close_handles() noexcept {
  if (reads_) reads_->stop();  // it reads with these handles
  for (Hid* handle : {&x_, &y_, &t_, &p_}) {
    if (*handle >= 0) H5Dclose(*handle);
    *handle = -1;
  }
  for (const Hid column : float_columns_) H5Dclose(column);
  float_columns_.clear();
  if (file_ >= 0) H5Fclose(file_);
  file_ = -1;
}

bool Hdf5Reader::open_float_columns(std::span<const char* const> names) {
  const Hdf5ErrorSilencer silence;
  if (layout_ != "evlife" || file_ < 0) return false;
  const auto present = std::count_if(names.begin(), names.end(), [&](const char* name) { return exists(file_, name); });
  if (present == 0) return false;
  const char* held = *std::find_if(names.begin(), names.end(), [&](const char* name) { return exists(file_, name); });
  for (const char* name : names) {
    const std::string why = !exists(file_, name) ? "is missing (the file holds '" + std::string(held) + "')" : "";
    if (!why.empty()) throw ReadError(path_, -1, -1, "HDF5 dataset '" + std::string(name) + "' " + why);
    const Hid column = open_column(name);
    float_columns_.push_back(column);
    float_names_.emplace_back(name);
    if (!is_float(column) || length_1d(column) != total_) {
      throw ReadError(path_, -1, -1,
                      "HDF5 dataset '" + std::string(name) + "' is not a 1-D floating-point column of the length of '" +
                          column_names_[0] + "' (" + std::to_string(total_) + ")");
    }
  }
  return true;
}

void Hdf5Reader::read_float_rows(std::int64_t first, std::size_t count, std::span<float* const> out) const {
  const Hdf5ErrorSilencer silence;
  for (std::size_t c = 0; c < float_columns_.size() && c < out.size(); ++c) {
    if (!read_slab(*reads_, float_columns_[c], H5T_NATIVE_FLOAT, first, count, out[c])) {
      throw ReadError(path_, -1, first,
                      "HDF5 dataset '" + float_names_[c] + "' cannot be read from event " + std::to_string(first) +
                          why_unread("corrupt data, a value no float holds, or a compression filter this HDF5 lacks"));
    }
  }
}

void Hdf5Reader::load_chunk() {
  const Hdf5ErrorSilencer silence;
  const std::size_t count =
      static_cast<std::size_t>(std::min<std::int64_t>(total_ - next_, kChunkEvents));
  chunk_pos_ = 0;
  chunk_size_ = 0;
  bool ok;
  const char* what = "CD/events";
  if (layout_ == "prophesee") {
    const hid_t type = H5Tcreate(H5T_COMPOUND, sizeof(CdRecord));
    H5Tinsert(type, "x", offsetof(CdRecord, x), H5T_NATIVE_UINT16);
    H5Tinsert(type, "y", offsetof(CdRecord, y), H5T_NATIVE_UINT16);
    H5Tinsert(type, "p", offsetof(CdRecord, p), H5T_NATIVE_INT16);
    H5Tinsert(type, "t", offsetof(CdRecord, t), H5T_NATIVE_INT64);
    ok = read_slab(*reads_, t_, type, next_, count, records_.data());
    H5Tclose(type);
  } else if (is_table()) {
    what = table_name_.c_str();
    ok = read_slab(*reads_, t_, H5T_NATIVE_DOUBLE, next_, count, doubles_.data(), 4);
    if (ok) {
      chunk_size_ = count;
      load_table_chunk(count);
      return;
    }
  } else {
    ok = read_columns(count, what);
    if (!ok) {
      // A value its column cannot hold: the rows before it are events.
      const hid_t columns[4] = {x_, y_, t_, p_};
      const ColumnKind kinds[4] = {ColumnKind::coordinate, ColumnKind::coordinate, ColumnKind::time_us,
                                   ColumnKind::polarity};
      std::optional<std::pair<std::size_t, double>> bad;
      int bad_column = 0;
      for (int c = 0; c < 4; ++c) {
        if (c == 2 && t_float_) continue;  // doubles: nothing to convert
        const auto row = first_unconvertible_row(*reads_, columns[c], kinds[c], next_, count);
        if (row && (!bad || row->first < bad->first)) bad = row, bad_column = c;
      }
      if (bad && (bad->first == 0 || read_columns(bad->first, what))) {
        if (!(t_float_ ? convert_float_times(bad->first) : convert_integer_times(bad->first)))
          return;  // an earlier row has no time
        stop_at(bad->first, column_names_[bad_column].c_str(), bad->second,
                kinds[bad_column] == ColumnKind::coordinate ? ", not a pixel coordinate"
                : kinds[bad_column] == ColumnKind::polarity ? ", not a polarity"
                                                            : ", not a time in whole microseconds");
        return;
      }
    }
    if (ok) {
      chunk_size_ = count;
      if (t_float_) convert_float_times(count);
      else convert_integer_times(count);
      return;
    }
  }
  if (!ok) {
    error_.emplace(path_, -1, next_,
                   "HDF5 dataset '" + std::string(what) + "' cannot be read from event " + std::to_string(next_) +
                       why_unread("corrupt data, wrong type or a compression filter this HDF5 lacks"));
    return;
  }
  chunk_size_ = count;
}

// The column datasets' rows [next_, next_ + count) into the column buffers
// (times in seconds into doubles_); `what` names the column that failed.
bool Hdf5Reader::read_columns(std::size_t count, const char*& what) {
  return (what = column_names_[0].c_str(), read_slab(*reads_, x_, H5T_NATIVE_UINT16, next_, count, xs_.data())) &&
         (what = column_names_[1].c_str(), read_slab(*reads_, y_, H5T_NATIVE_UINT16, next_, count, ys_.data())) &&
         (what = column_names_[2].c_str(),
          t_float_ ? read_slab(*reads_, t_, H5T_NATIVE_DOUBLE, next_, count, doubles_.data())
                        : read_slab(*reads_, t_, H5T_NATIVE_INT64, next_, count, ts_.data())) &&
         (what = column_names_[3].c_str(), read_slab(*reads_, p_, H5T_NATIVE_INT8, next_, count, ps_.data()));
}

// Converts the chunk's rows in doubles_ into the column buffers. At the first
// row that is no event (a coordinate that is no pixel, a time out of range)
// the chunk ends before it and error_ names it: the rows before are read.
bool Hdf5Reader::load_table_chunk(std::size_t count) {
  for (std::size_t i = 0; i < count; ++i) {
    const double* row = &doubles_[4 * i];
    if (!to_coordinate(row[table_.x], xs_[i])) return stop_at(i, "x", row[table_.x], ", not a pixel coordinate");
    if (!to_coordinate(row[table_.y], ys_[i])) return stop_at(i, "y", row[table_.y], ", not a pixel coordinate");
    if (!detail::float_time_to_us(row[table_.t], t_unit_ns_, ts_[i])) return stop_at(i, "t", row[table_.t], ", no time");
    ps_[i] = row[table_.p] > 0 ? std::int8_t{1} : std::int8_t{-1};
  }
  return true;
}

bool Hdf5Reader::convert_float_times(std::size_t count) {
  for (std::size_t i = 0; i < count; ++i) {
    if (!detail::float_time_to_us(doubles_[i], t_unit_ns_, ts_[i])) return stop_at(i, "t", doubles_[i], ", no time");
  }
  return true;
}

bool Hdf5Reader::convert_integer_times(std::size_t count) {
  if (t_unit_ns_ == 1000) return true;
  for (std::size_t i = 0; i < count; ++i) {
    const std::int64_t value = ts_[i];
    if (!detail::integer_time_to_us(value, t_unit_ns_, ts_[i]))
      return stop_at(i, "t", static_cast<double>(value), ", no time in int64 microseconds");
  }
  return true;
}

void Hdf5Reader::choose_time_unit(const std::string& time_unit) {
  const std::int64_t given = time_unit.empty() ? 0 : detail::unit_ns(time_unit);
  if (!time_unit.empty() && given == 0) {
    close_handles();
    throw ReadError(path_, -1, -1, "--time-unit " + time_unit + ": not a unit (s, ms, us or ns)");
  }
  if (layout_ == "prophesee") {  // its t field is µs by the layout's definition
    if (given != 0 && given != 1000) {
      close_handles();
      throw ReadError(path_, -1, -1, "--time-unit " + time_unit + ": the Prophesee layout's t is in microseconds");
    }
    return;
  }
  std::int64_t stated = 0;
  if (!is_table() && given == 0) {
    if (const auto units = read_string_attribute(t_, "units")) {
      stated = detail::unit_ns(*units);
      if (stated == 0) {  // read in another unit, the times would be off by 1000s
        close_handles();
        throw ReadError(path_, -1, -1, "HDF5 dataset '" + column_names_[2] + "' states units '" + *units +
                                           "', not a time unit (s, ms, us, ns): --time-unit U says which");
      }
    }
  }
  t_unit_ns_ = given != 0 ? given : stated != 0 ? stated : t_float_ ? 1'000'000'000 : 1000;
}

// As the readers of other formats that state a sensor: an event outside it
// is an error at its index (`info`, which reads unchecked, said nothing).
void Hdf5Reader::stop_outside_sensor() {
  if (!sensor_) return;
  const bool compound = layout_ == "prophesee";
  for (std::size_t i = 0; i < chunk_size_; ++i) {
    const int x = compound ? records_[i].x : xs_[i];
    const int y = compound ? records_[i].y : ys_[i];
    if (sensor_->contains(x, y)) continue;
    error_.emplace(path_, -1, next_ + static_cast<std::int64_t>(i),
                   "event at (x " + std::to_string(x) + ", y " + std::to_string(y) + ") is outside the " +
                       std::to_string(sensor_->width) + "x" + std::to_string(sensor_->height) +
                       " sensor the file states");
    chunk_size_ = i;
    return;
  }
}

// Row i of the chunk is no event: the chunk ends before it, error_ names it.
bool Hdf5Reader::stop_at(std::size_t i, const char* column, double value, const char* why) {
  const std::int64_t index = next_ + static_cast<std::int64_t>(i);
  error_.emplace(path_, -1, index,
                 "HDF5 " + std::string(layout_) + " layout: event " + std::to_string(index) + " has " + column +
                     " = " + shortest_text(value) + why + " (corrupt data?)");
  chunk_size_ = i;
  return false;
}

bool Hdf5Reader::read_time(std::int64_t index, std::int64_t& t_us) const {
  std::int64_t t = 0;
  bool ok;
  if (layout_ == "prophesee") {  // the compound's t field alone
    const hid_t type = H5Tcreate(H5T_COMPOUND, sizeof(std::int64_t));
    H5Tinsert(type, "t", 0, H5T_NATIVE_INT64);
    ok = read_slab(*reads_, t_, type, index, 1, &t);
    H5Tclose(type);
  } else if (is_table() || t_float_) {
    double value = 0.0;
    ok = (is_table() ? read_slab(*reads_, t_, H5T_NATIVE_DOUBLE, index, 1, &value, 4, table_.t)
                     : read_slab(*reads_, t_, H5T_NATIVE_DOUBLE, index, 1, &value)) &&
         detail::float_time_to_us(value, t_unit_ns_, t);
  } else {
    std::int64_t value = 0;
    ok = read_slab(*reads_, t_, H5T_NATIVE_INT64, index, 1, &value) && detail::integer_time_to_us(value, t_unit_ns_, t);
  }
  t_us = t + t_offset_us_;
  return ok;
}

std::int64_t Hdf5Reader::skip_events_before(std::int64_t t_us) {
  if (!unread()) return 0;
  const Hdf5ErrorSilencer silence;
  std::int64_t lo = 0, hi = total_;  // the answer lies in [lo, hi]
  while (lo < hi) {
    const std::int64_t mid = lo + (hi - lo) / 2;
    std::int64_t t = 0;
    if (!read_time(mid, t)) return 0;  // unreadable: read from the start, where read() reports it
    if (t < t_us) lo = mid + 1;
    else hi = mid;
  }
  next_ = lo;
  return lo;
}

std::optional<std::int64_t> Hdf5Reader::first_event_time_us() const {
  if (!unread() || total_ == 0) return std::nullopt;
  const Hdf5ErrorSilencer silence;
  std::int64_t t = 0;
  if (!read_time(0, t)) return std::nullopt;
  return t;
}

std::size_t Hdf5Reader::read(std::span<Event> out) {
  if (error_ && chunk_pos_ == chunk_size_) throw *error_;
  std::size_t n = 0;
  while (n < out.size()) {
    if (chunk_pos_ == chunk_size_) {
      if (error_ || next_ >= total_) break;
      load_chunk();  // on an error: the events before it, then the error
      stop_outside_sensor();
      next_ += static_cast<std::int64_t>(chunk_size_);
      if (chunk_size_ == 0) break;
    }
    const std::size_t count = std::min(chunk_size_ - chunk_pos_, out.size() - n);
    if (layout_ == "prophesee") {
      for (std::size_t i = 0; i < count; ++i) {
        const CdRecord& r = records_[chunk_pos_ + i];
        out[n + i] = Event{r.t, r.x, r.y, r.p > 0 ? std::int8_t{1} : std::int8_t{-1}};
      }
    } else {
      for (std::size_t i = 0; i < count; ++i) {
        const std::size_t k = chunk_pos_ + i;
        out[n + i] = Event{ts_[k] + t_offset_us_, xs_[k], ys_[k],
                           ps_[k] > 0 ? std::int8_t{1} : std::int8_t{-1}};
      }
    }
    chunk_pos_ += count;
    n += count;
  }
  if (error_ && n == 0) throw *error_;
  return n;
}

namespace detail {
namespace {

SniffResult sniff_hdf5(std::span<const std::byte> head, std::string_view path) {
  if (starts_with_hdf5_signature(head.data(), head.size())) {
    return SniffResult::by_content;
  }
  return has_extension(path, ".h5") || has_extension(path, ".hdf5") ? SniffResult::by_extension
                                                                     : SniffResult::no;
}

std::unique_ptr<EventReader> open_hdf5(const std::string& path, const ReaderOptions& options) {
  return std::make_unique<Hdf5Reader>(path, options.topic, options.time_unit);  // MVSEC's, M3ED's camera
}

}  // namespace

const ReaderFormat hdf5_format{"hdf5",
                               "HDF5 events: DSEC events/{x,y,t,p}, event_utils events/{xs,ys,ts,ps}, "
                               "Prophesee CD/events, MVSEC davis/left/events, M3ED prophesee/left/{x,y,t,p}, v2e "
                               "events (N×4), or evlife x,y,t,p",
                               &sniff_hdf5, nullptr, &open_hdf5, nullptr, "topic, time-unit"};

}  // namespace detail
}  // namespace evlife::io
