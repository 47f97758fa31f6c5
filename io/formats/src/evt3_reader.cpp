#include "evt3_reader.h"

#include <algorithm>
#include <memory>

#include "prophesee_header.h"
#include "reader_registry.h"

namespace evlife::io {
Evt3Reader::Evt3Reader(const std::string& path) : file_(path) {
  const PropheseeHeader header = read_prophesee_header(file_);
  const std::string version = header.evt_version();
  if (version != "3.0") {
    throw ReadError(path, 0, -1,
                    "not a Prophesee EVT 3.0 RAW file (header says evt '" + version + "')");
  }
  sensor_ = header.sensor_size();
  if (sensor_) {
    decoder_.set_geometry(static_cast<std::uint32_t>(std::max(sensor_->width, 0)),
                          static_cast<std::uint32_t>(std::max(sensor_->height, 0)));
  }
}

std::size_t Evt3Reader::decode(std::span<Event> out) {
  constexpr std::size_t kWordBytes = Evt3Decoder::kWordBytes;
  const Evt3Decoder::Result r = decoder_.decode(file_.data(), file_.available() / kWordBytes, out);
  if (r.fault) {
    const std::int64_t back = r.fault_began_a_word_before ? std::int64_t{kWordBytes} : 0;
    error_.emplace(path(), file_.offset() + static_cast<std::int64_t>(r.words * kWordBytes) - back,
                   event_count_ + static_cast<std::int64_t>(r.events), decoder_.fault_message());
  }
  file_.consume(r.words * kWordBytes);
  event_count_ += static_cast<std::int64_t>(r.events);
  return r.events;
}

std::size_t Evt3Reader::read(std::span<Event> out) {
  if (out.empty()) return 0;
  std::size_t n = 0;
  // Events left over from a vector word that did not fit last time.
  while (pending_begin_ < pending_end_ && n < out.size()) out[n++] = pending_[pending_begin_++];
  if (n == out.size() && n > 0) return n;
  if (error_) {
    if (n > 0) return n;
    throw *error_;
  }
  while (!error_) {
    if (file_.fill(Evt3Decoder::kWordBytes) < Evt3Decoder::kWordBytes) {
      if (file_.available() != 0) {
        error_.emplace(path(), file_.offset(), event_count_, "truncated EVT 3.0 word (1 trailing byte)");
      }
      break;
    }
    if (out.size() - n >= kMaxEventsPerWord) {
      n += decode(out.subspan(n));
    } else if (n == 0) {
      // Caller buffer smaller than one vector word: decode aside, hand out a part.
      pending_begin_ = 0;
      pending_end_ = decode(std::span<Event>(pending_.data(), pending_.size()));
      while (pending_begin_ < pending_end_ && n < out.size()) out[n++] = pending_[pending_begin_++];
      if (n > 0) break;
    } else {
      break;
    }
  }
  if (error_ && n == 0) throw *error_;
  return n;
}

namespace detail {
namespace {

SniffResult sniff_evt3(std::span<const std::byte> head, std::string_view /*path*/) {
  return is_prophesee_raw(head, "3.0") ? SniffResult::by_content : SniffResult::no;
}

std::unique_ptr<EventReader> open_evt3(const std::string& path) {
  return std::make_unique<Evt3Reader>(path);
}

}  // namespace

const ReaderFormat evt3_format{"evt3", "Prophesee RAW EVT 3.0 (.raw, '% evt 3.0' header)",
                               &sniff_evt3, &open_evt3};

}  // namespace detail
}  // namespace evlife::io
