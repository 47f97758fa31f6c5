#include "evlife/io/stop.h"

namespace evlife::io {
namespace {
std::atomic<const std::atomic<bool>*> g_stop_flag{nullptr};
}  // namespace

void set_stop_flag(const std::atomic<bool>* flag) noexcept { g_stop_flag.store(flag); }

bool stop_requested() noexcept {
  const std::atomic<bool>* flag = g_stop_flag.load();
  return flag != nullptr && flag->load(std::memory_order_relaxed);
}

}  // namespace evlife::io
