// The augmented stream to a file: adapts io's AugmentedEventWriter (CSV or
// the binary format, by extension) to the engine's sink.
#pragma once

#include <memory>
#include <span>
#include <utility>

#include "evlife/engine/augmented_sink.h"
#include "evlife/io/augmented_event_writer.h"

namespace evlife::engine {

class WriterSink final : public AugmentedSink {
 public:
  explicit WriterSink(std::unique_ptr<io::AugmentedEventWriter> writer)
      : writer_(std::move(writer)) {}
  void write(std::span<const AugmentedEvent> events) override { writer_->write(events); }
  void finish() override { writer_->close(); }  // flushes; throws io::WriteError on failure

 private:
  std::unique_ptr<io::AugmentedEventWriter> writer_;
};

}  // namespace evlife::engine
