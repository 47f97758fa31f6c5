#include "evlife/io/stop.h"

namespace evlife::io {
namespace {
std::atomic<const std::atomic<bool>*> g_stop_flag{nullptr};
thread_local ThreadStopCheck t_check = nullptr;
thread_local void* t_check_context = nullptr;
}  // namespace

void set_stop_flag(const std::atomic<bool>* flag) noexcept { g_stop_flag.store(flag); }

void set_thread_stop_check(ThreadStopCheck check, void* context) noexcept {
  t_check = check;
  t_check_context = context;
}

bool stop_requested() noexcept {
  const std::atomic<bool>* flag = g_stop_flag.load();
  if (flag != nullptr && flag->load(std::memory_order_relaxed)) return true;
  return t_check != nullptr && t_check(t_check_context);
}

}  // namespace evlife::io
