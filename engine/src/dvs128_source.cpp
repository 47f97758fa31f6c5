#include "evlife/engine/dvs128_source.h"

#include <exception>
#include <stdexcept>
#include <utility>

namespace evlife::engine {

Dvs128Source::Dvs128Source(const Options& options)
    : wait_(options.wait),
      on_transfer_(options.on_transfer),
      on_transfer_user_(options.on_transfer_user) {
  io::Dvs128DeviceOptions dev;
  dev.serial = options.serial;
  dev.biases = options.biases;
  dev.transfer_count = options.transfer_count;
  dev.transfer_bytes = options.transfer_bytes;
  device_ = std::make_unique<io::Dvs128Device>(dev);
}

Dvs128Source::~Dvs128Source() = default;  // the device stops and closes itself

std::string Dvs128Source::describe() const { return "usb:" + device_->info().describe(); }

void Dvs128Source::finish(SourceStatus status, std::string message) noexcept {
  error_ = std::move(message);
  status_.store(status, std::memory_order_release);
}

// Decodes ready transfers into `out`; releases (resubmits) each one fully decoded.
std::size_t Dvs128Source::drain(std::span<Event> out) noexcept {
  std::size_t n = 0;
  while (n < out.size() && device_->has_data()) {
    const auto chunk = device_->front();
    if (chunk_offset_ == 0 && on_transfer_ != nullptr) {
      on_transfer_(on_transfer_user_, chunk.completed_ns);
    }
    const auto r = decoder_.decode(chunk.bytes.subspan(chunk_offset_), out.subspan(n));
    n += r.events_written;
    chunk_offset_ += r.bytes_consumed;
    if (chunk_offset_ < chunk.bytes.size()) break;  // `out` is full
    chunk_offset_ = 0;
    device_->release_front();
  }
  return n;
}

std::size_t Dvs128Source::pull(std::span<Event> out) noexcept {
  if (status() != SourceStatus::ok || out.empty()) return 0;
  try {
    if (!started_ && !stop_.load(std::memory_order_relaxed)) {
      started_ = true;
      device_->start();
    }
    for (int round = 0; round < 2; ++round) {
      if (const std::size_t n = drain(out); n > 0) return n;
      const io::Dvs128State state = device_->state();
      if (state == io::Dvs128State::streaming && !stop_.load(std::memory_order_relaxed)) {
        if (round == 0) device_->handle_events(wait_);  // callbacks queue completed transfers
        continue;
      }
      if (state == io::Dvs128State::streaming || state == io::Dvs128State::opened) {
        device_->stop();  // stop requested: cancel, reap, STOP; ready data is still drained
        continue;
      }
      if (state == io::Dvs128State::vanished || state == io::Dvs128State::failed) {
        // Reap what is still in flight: data completed before the fault comes first.
        for (int i = 0; i < 100 && device_->transfers_in_flight() > 0; ++i) {
          device_->handle_events(std::chrono::milliseconds(10));
        }
        if (device_->has_data()) continue;
        const auto& c = decoder_.counters();
        finish(SourceStatus::error,
               device_->error_message() + " after " + std::to_string(c.pixel_events) +
                   " events (" + std::to_string(device_->bytes_received()) + " bytes read)");
        return 0;
      }
      if (!device_->has_data()) {  // stopped and drained
        finish(SourceStatus::end_of_stream, {});
        return 0;
      }
    }
    return 0;
  } catch (const std::exception& e) {
    finish(SourceStatus::error, e.what());
  } catch (...) {
    finish(SourceStatus::error, describe() + ": unknown error");
  }
  return 0;
}

bool is_dvs128_spec(std::string_view spec) {
  return spec == "dvs128" || spec.substr(0, 7) == "dvs128:";
}

namespace {

void require_dvs128_spec(std::string_view spec) {
  if (!is_dvs128_spec(spec)) {
    throw std::invalid_argument("not a DVS128 source spec: '" + std::string(spec) +
                                "' (expected dvs128 or dvs128:SERIAL)");
  }
}

}  // namespace

std::unique_ptr<Dvs128Source> make_dvs128_source(std::string_view spec,
                                                 const std::string& biases_file) {
  require_dvs128_spec(spec);  // named before the bias file
  return make_dvs128_source(spec, biases_file.empty() ? io::Dvs128Biases{} : io::Dvs128Biases::load_file(biases_file));
}

std::unique_ptr<Dvs128Source> make_dvs128_source(std::string_view spec, const io::Dvs128Biases& biases) {
  require_dvs128_spec(spec);
  Dvs128Source::Options options;
  if (spec.size() > 7) options.serial = std::string(spec.substr(7));
  options.biases = biases;
  return std::make_unique<Dvs128Source>(options);
}

}  // namespace evlife::engine
