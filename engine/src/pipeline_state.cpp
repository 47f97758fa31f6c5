#include "evlife/engine/pipeline_state.h"

#include <stdexcept>

namespace evlife::engine {
namespace {
const EngineOptions& checked(const EngineOptions& options) {
  const std::string problem = validate_engine_options(options);
  if (!problem.empty()) throw std::invalid_argument(problem);
  return options;
}
}  // namespace

// Queue capacities cover every batch of the pool, so a try_enqueue never
// finds the queue full (the pool, not the queue, is where overload shows).
WorkerChannel::WorkerChannel(std::size_t batches, std::size_t batch_events, int worker)
    : free(batches, 3, 0), in(batches, 1, 0), out(batches, 1, 0) {
  pool.reserve(batches);
  moodycamel::ProducerToken token(free);
  for (std::size_t i = 0; i < batches; ++i) {
    pool.push_back(std::make_unique<WorkBatch>(batch_events));
    pool.back()->worker = worker;
    free.enqueue(token, pool.back().get());
  }
}

PipelineState::PipelineState(const EngineOptions& opts, SensorSize sensor, OverloadPolicy pol)
    : options(checked(opts)),
      policy(pol),
      layout(sensor, opts.workers, opts.tiles_x, opts.tiles_y, effective_margin_px(opts)),
      order_free(opts.batches_per_worker * static_cast<std::size_t>(opts.workers), 2, 0),
      order(opts.batches_per_worker * static_cast<std::size_t>(opts.workers), 1, 0) {
  options.lifetime.sensor = sensor;
  for (int w = 0; w < opts.workers; ++w)
    workers.push_back(std::make_unique<WorkerChannel>(opts.batches_per_worker,
                                                      opts.batch_events, w));
  // One merge-order batch per source chunk in flight; a chunk holds at most
  // one batch per worker, so this many never limit more than the workers do.
  const std::size_t orders = opts.batches_per_worker * static_cast<std::size_t>(opts.workers);
  order_pool.reserve(orders);
  moodycamel::ProducerToken token(order_free);
  for (std::size_t i = 0; i < orders; ++i) {
    order_pool.push_back(std::make_unique<OrderBatch>(opts.batch_events));
    order_free.enqueue(token, order_pool.back().get());
  }
  if (opts.render_batches > 0)
    render_tap = std::make_unique<RenderTap>(opts.render_batches, opts.batch_events, wake_merger);
}

}  // namespace evlife::engine
