// HDF5 writers (see evlife/io/hdf5_writer.h): one column buffer per dataset,
// flushed as one hyperslab per column every kChunkEvents events.
#include "evlife/io/hdf5_writer.h"

#include <hdf5.h>
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <cstdint>
#include <span>
#include <vector>

#include "evlife/io/output_path.h"
#include "hdf5_error_silencer.h"

namespace evlife::io {
namespace {

constexpr std::size_t kChunkEvents = 1 << 16;
constexpr unsigned kDeflateLevel = 1;  // fast; shuffle does most of the work
// Room kept free on the disk for H5Fclose, which writes the file's metadata.
// libhdf5 1.10 (Debian 12) cannot survive a failed close: the file's id
// dangles and its exit handler crashes (HDF5 issue #2257, fixed in 1.14), so
// a chunk that would leave less than this is not written and the file closes
// whole with the events before it.
constexpr std::uint64_t kCloseReserveBytes = 2u << 20;

std::atomic<bool> g_close_failed{false};
std::atomic<bool> g_create_failed{false};

// Free bytes for an unprivileged writer on the file system holding `path`;
// UINT64_MAX when unknown.
std::uint64_t free_bytes(const std::string& path) noexcept {
  struct statvfs fs {};
  if (statvfs(path.c_str(), &fs) != 0) return UINT64_MAX;
  return static_cast<std::uint64_t>(fs.f_bavail) * static_cast<std::uint64_t>(fs.f_frsize);
}

// Bytes the file at `path` may still grow by under the process's file size
// limit (ulimit -f: a write past it fails as a full disk's does, and the file
// could not be closed); UINT64_MAX when unlimited or unknown.
std::uint64_t bytes_below_size_limit(const std::string& path) noexcept {
  rlimit limit{};
  struct stat st {};
  if (getrlimit(RLIMIT_FSIZE, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY || ::stat(path.c_str(), &st) != 0)
    return UINT64_MAX;
  const auto size = static_cast<std::uint64_t>(st.st_size);
  return limit.rlim_cur > size ? limit.rlim_cur - size : 0;
}

struct ColumnSpec {
  const char* name;
  hid_t file_type;    // resolved at run time (HDF5 type ids are not constants)
  hid_t memory_type;
  const char* units;
  const char* description;
};

// Column buffers: one typed vector per dataset, in dataset order.
struct Columns {
  std::vector<std::uint16_t> x, y;
  std::vector<std::int64_t> t;
  std::vector<std::int8_t> p;
  std::vector<float> lifetime, vx, vy, prediction_error;
  const void* data(std::size_t column) const {
    switch (column) {
      case 0: return x.data();
      case 1: return y.data();
      case 2: return t.data();
      case 3: return p.data();
      case 4: return lifetime.data();
      case 5: return vx.data();
      case 6: return vy.data();
      default: return prediction_error.data();
    }
  }
};

class Hdf5ColumnFile {
 public:
  Hdf5ColumnFile(const std::string& path, std::optional<SensorSize> sensor, bool augmented)
      : path_(path), column_count_(augmented ? 8 : 4) {
    const std::string folder_problem = create_output_folders(path);
    if (const auto problem = seekable_output_problem(path, "an HDF5 file is written by seeking within it")) {
      throw WriteError(path, *problem);
    }
    // libhdf5 does not say why a create failed: the same open says it.
    if (const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0644); fd < 0) {
      const int err = errno;
      throw WriteError(path, folder_problem.empty() ? std::string("cannot create: ") + std::strerror(err) : folder_problem,
                       err);
    } else {
      ::close(fd);
    }
    const Hdf5ErrorSilencer silence;
    file_ = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    if (file_ < 0) {
      g_create_failed.store(true);
      throw WriteError(path, "cannot create the HDF5 file (a full disk, or another program holding it open: HDF5 locks it)");
    }
    try {
      const std::array<ColumnSpec, 8> specs{{
          {"x", H5T_STD_U16LE, H5T_NATIVE_UINT16, "px", "column, 0 = left"},
          {"y", H5T_STD_U16LE, H5T_NATIVE_UINT16, "px", "row, 0 = top"},
          {"t", H5T_STD_I64LE, H5T_NATIVE_INT64, "us", "timestamp, microseconds"},
          {"p", H5T_STD_I8LE, H5T_NATIVE_INT8, "1", "polarity: +1 ON (brighter), -1 OFF"},
          {"lifetime", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, "us",
           "time the edge needs to move one pixel; 0 = noise"},
          {"vx", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, "px/s", "normal velocity (perpendicular to the edge), x"},
          {"vy", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, "px/s", "normal velocity (perpendicular to the edge), y"},
          {"prediction_error", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, "us",
           "t minus the time predicted by an earlier event; NaN = no prediction"},
      }};
      for (std::size_t c = 0; c < column_count_; ++c) {
        create_dataset(c, specs[c]);
        memory_types_[c] = specs[c].memory_type;
        event_bytes_ += H5Tget_size(specs[c].memory_type);
      }
      write_string_attribute(file_, "generator", "evlife");
      write_string_attribute(file_, "layout",
                             augmented ? "evlife augmented events: x,y,t,p,lifetime,vx,vy,prediction_error"
                                       : "evlife events: x,y,t,p");
      if (sensor) {
        write_int_attribute(file_, "width", sensor->width);
        write_int_attribute(file_, "height", sensor->height);
      }
    } catch (...) {
      close_noexcept();
      throw;
    }
    columns_.x.reserve(kChunkEvents);
    columns_.y.reserve(kChunkEvents);
    columns_.t.reserve(kChunkEvents);
    columns_.p.reserve(kChunkEvents);
    if (augmented) {
      columns_.lifetime.reserve(kChunkEvents);
      columns_.vx.reserve(kChunkEvents);
      columns_.vy.reserve(kChunkEvents);
      columns_.prediction_error.reserve(kChunkEvents);
    }
  }

  ~Hdf5ColumnFile() { close_noexcept(); }
  Hdf5ColumnFile(const Hdf5ColumnFile&) = delete;
  Hdf5ColumnFile& operator=(const Hdf5ColumnFile&) = delete;

  const std::string& path() const { return path_; }

  void append(const Event& e) {
    columns_.x.push_back(e.x);
    columns_.y.push_back(e.y);
    columns_.t.push_back(e.t_us);
    columns_.p.push_back(e.p);
    if (columns_.x.size() == kChunkEvents) flush();
  }

  void append(const AugmentedEvent& a) {
    columns_.lifetime.push_back(a.lifetime_us);
    columns_.vx.push_back(a.vx_px_s);
    columns_.vy.push_back(a.vy_px_s);
    columns_.prediction_error.push_back(a.prediction_error_us);
    append(a.event);
  }

  void close() {
    if (file_ < 0) return;
    if (failed_) throw WriteError(path_, "an earlier write failed", 0, written_);
    flush();
    const Hdf5ErrorSilencer silence;
    bool ok = true;
    for (std::size_t c = 0; c < column_count_; ++c) ok = H5Dclose(datasets_[c]) >= 0 && ok;
    datasets_.fill(-1);
    const bool closed = H5Fclose(file_) >= 0;
    if (!closed) g_close_failed.store(true);
    file_ = -1;
    if (!ok || !closed) throw WriteError(path_, "closing the HDF5 file failed (disk full?)", EIO);
  }

 private:
  void create_dataset(std::size_t c, const ColumnSpec& spec) {
    const hsize_t initial[1] = {0};
    const hsize_t maximum[1] = {H5S_UNLIMITED};
    const hsize_t chunk[1] = {kChunkEvents};
    const hid_t space = H5Screate_simple(1, initial, maximum);
    const hid_t properties = H5Pcreate(H5P_DATASET_CREATE);
    // No modification times (HDF5 stores them by default): the same events
    // give the same file, byte for byte.
    const bool ok = space >= 0 && properties >= 0 && H5Pset_chunk(properties, 1, chunk) >= 0 &&
                    H5Pset_shuffle(properties) >= 0 && H5Pset_deflate(properties, kDeflateLevel) >= 0 &&
                    H5Pset_obj_track_times(properties, 0) >= 0 &&
                    (datasets_[c] = H5Dcreate2(file_, spec.name, spec.file_type, space, H5P_DEFAULT,
                                               properties, H5P_DEFAULT)) >= 0;
    if (properties >= 0) H5Pclose(properties);
    if (space >= 0) H5Sclose(space);
    if (!ok) throw WriteError(path_, std::string("cannot create HDF5 dataset '") + spec.name + "'");
    write_string_attribute(datasets_[c], "units", spec.units);
    write_string_attribute(datasets_[c], "description", spec.description);
  }

  void write_string_attribute(hid_t object, const char* name, const std::string& value) {
    const hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, H5T_VARIABLE);
    H5Tset_cset(type, H5T_CSET_UTF8);  // h5py returns str, not bytes
    const hid_t space = H5Screate(H5S_SCALAR);
    const hid_t attribute = H5Acreate2(object, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
    const char* text = value.c_str();
    const bool ok = attribute >= 0 && H5Awrite(attribute, type, &text) >= 0;
    if (attribute >= 0) H5Aclose(attribute);
    H5Sclose(space);
    H5Tclose(type);
    if (!ok) throw WriteError(path_, std::string("cannot write HDF5 attribute '") + name + "'");
  }

  void write_int_attribute(hid_t object, const char* name, int value) {
    const hid_t space = H5Screate(H5S_SCALAR);
    const hid_t attribute = H5Acreate2(object, name, H5T_STD_I32LE, space, H5P_DEFAULT, H5P_DEFAULT);
    const bool ok = attribute >= 0 && H5Awrite(attribute, H5T_NATIVE_INT, &value) >= 0;
    if (attribute >= 0) H5Aclose(attribute);
    H5Sclose(space);
    if (!ok) throw WriteError(path_, std::string("cannot write HDF5 attribute '") + name + "'");
  }

  void flush() {
    const std::size_t count = columns_.x.size();
    if (count == 0 || file_ < 0) return;
    // The chunks and metadata libhdf5 still holds in its caches are not in the
    // file's size yet (a run that passed this check then failed to close):
    // written out first, so that the size measured is what the file takes.
    if (const Hdf5ErrorSilencer silence; H5Fflush(file_, H5F_SCOPE_LOCAL) < 0) {
      failed_ = true;
      throw WriteError(path_, "writing HDF5 events before " + std::to_string(written_) + " failed (disk full?)");
    }
    // The chunk uncompressed: an upper bound of what it takes on disk.
    const std::uint64_t free = free_bytes(path_), below_limit = bytes_below_size_limit(path_);
    if (const std::uint64_t room = std::min(free, below_limit); room < count * event_bytes_ + kCloseReserveBytes) {
      failed_ = true;  // nothing of this chunk written: the file closes whole
      const bool limit = below_limit < free;
      throw WriteError(path_,
                       (limit ? "the file size limit (ulimit -f) is near (" + std::to_string(room >> 10) + " KiB below it)"
                              : "the disk is nearly full (" + std::to_string(room >> 10) + " KiB free)") +
                           ": events " + std::to_string(written_) + ".." + std::to_string(written_ + count) +
                           " not written, so that the HDF5 file can still be closed with the " +
                           std::to_string(written_) + " before them",
                       limit ? EFBIG : ENOSPC, written_);
    }
    const Hdf5ErrorSilencer silence;
    const hsize_t start[1] = {written_};
    const hsize_t size[1] = {count};
    const hsize_t extent[1] = {written_ + count};
    const hid_t memory_space = H5Screate_simple(1, size, nullptr);
    for (std::size_t c = 0; c < column_count_; ++c) {
      hid_t file_space = -1;
      const bool ok = H5Dset_extent(datasets_[c], extent) >= 0 &&
                      (file_space = H5Dget_space(datasets_[c])) >= 0 &&
                      H5Sselect_hyperslab(file_space, H5S_SELECT_SET, start, nullptr, size, nullptr) >= 0 &&
                      H5Dwrite(datasets_[c], memory_types_[c], memory_space, file_space, H5P_DEFAULT,
                               columns_.data(c)) >= 0;
      if (file_space >= 0) H5Sclose(file_space);
      if (!ok) {
        H5Sclose(memory_space);
        failed_ = true;
        throw WriteError(path_, "writing HDF5 events " + std::to_string(written_) + ".." +
                                    std::to_string(written_ + count) + " failed (disk full?)");
      }
    }
    H5Sclose(memory_space);
    written_ += count;
    columns_.x.clear();
    columns_.y.clear();
    columns_.t.clear();
    columns_.p.clear();
    columns_.lifetime.clear();
    columns_.vx.clear();
    columns_.vy.clear();
    columns_.prediction_error.clear();
  }

  void close_noexcept() noexcept {
    if (file_ < 0) return;
    const Hdf5ErrorSilencer silence;
    for (hid_t& dataset : datasets_) {
      if (dataset >= 0) H5Dclose(dataset);
      dataset = -1;
    }
    if (H5Fclose(file_) < 0) g_close_failed.store(true);
    file_ = -1;
  }

  std::string path_;
  std::size_t column_count_;
  std::uint64_t event_bytes_ = 0;  // one event in the columns' memory types
  hid_t file_ = -1;
  std::array<hid_t, 8> datasets_{-1, -1, -1, -1, -1, -1, -1, -1};
  std::array<hid_t, 8> memory_types_{};
  Columns columns_;
  hsize_t written_ = 0;
  bool failed_ = false;
};

class Hdf5AugmentedWriter final : public AugmentedEventWriter {
 public:
  Hdf5AugmentedWriter(const std::string& path, std::optional<SensorSize> sensor)
      : file_(path, sensor, true) {}
  void write(std::span<const AugmentedEvent> events) override {
    for (const AugmentedEvent& a : events) file_.append(a);
  }
  void close() override { file_.close(); }
  const std::string& path() const override { return file_.path(); }

 private:
  Hdf5ColumnFile file_;
};

class Hdf5EventWriter final : public EventWriter {
 public:
  Hdf5EventWriter(const std::string& path, std::optional<SensorSize> sensor)
      : file_(path, sensor, false) {}
  void write(std::span<const Event> events) override {
    for (const Event& e : events) file_.append(e);
  }
  void close() override { file_.close(); }
  const std::string& path() const override { return file_.path(); }

 private:
  Hdf5ColumnFile file_;
};

}  // namespace

std::unique_ptr<AugmentedEventWriter> open_hdf5_augmented_writer(const std::string& path,
                                                                 std::optional<SensorSize> sensor) {
  return std::make_unique<Hdf5AugmentedWriter>(path, sensor);
}

std::unique_ptr<EventWriter> open_hdf5_event_writer(const std::string& path,
                                                    std::optional<SensorSize> sensor) {
  return std::make_unique<Hdf5EventWriter>(path, sensor);
}

bool hdf5_exit_would_crash() noexcept { return g_close_failed.load(); }

bool hdf5_exit_would_loop() noexcept { return g_create_failed.load(); }

}  // namespace evlife::io
