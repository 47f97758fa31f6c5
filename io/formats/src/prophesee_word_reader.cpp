#include "prophesee_word_reader.h"

#include <algorithm>

#include "prophesee_header.h"

namespace evlife::io {

PropheseeWordReader::PropheseeWordReader(const std::string& path, std::string_view evt_version) : file_(path) {
  const PropheseeHeader header = read_prophesee_header(file_);
  const std::string version = header.evt_version();
  if (version != evt_version) {
    throw ReadError(path, 0, -1,
                    "not a Prophesee EVT " + std::string(evt_version) + " RAW file (header says evt '" + version + "')");
  }
  sensor_ = header.sensor_size();
  if (sensor_) {
    max_x_ = static_cast<std::uint32_t>(std::min(sensor_->width, 2048) - 1);
    max_y_ = static_cast<std::uint32_t>(std::min(sensor_->height, 2048) - 1);
  }
}

}  // namespace evlife::io
