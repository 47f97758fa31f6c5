#include "evlife/engine/realtime_options.h"

#include <stdexcept>

namespace evlife::engine {

std::string validate_realtime_options(const RealtimeOptions& o) {
  for (int cpu : o.cpus) {
    if (cpu < 0 || cpu > 1023) return "realtime.cpus: CPU " + std::to_string(cpu) + " must be in 0..1023";
  }
  if (o.rt_priority < 0 || o.rt_priority > 99)
    return "realtime.rt_priority: " + std::to_string(o.rt_priority) + " must be 0 (off) or 1..99 (SCHED_FIFO)";
  return {};
}

std::vector<int> parse_cpu_list(const std::string& text) {
  std::vector<int> cpus;
  std::size_t pos = 0;
  const auto number = [&](const std::string& part) {
    std::size_t used = 0;
    int v = -1;
    try {
      v = std::stoi(part, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != part.size() || part.empty() || v < 0)
      throw std::invalid_argument("--cpus " + text + ": '" + part + "' is not a CPU number");
    return v;
  };
  while (pos <= text.size()) {
    const std::size_t comma = text.find(',', pos);
    const std::string part = text.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
    const std::size_t dash = part.find('-');
    if (dash == std::string::npos) {
      cpus.push_back(number(part));
    } else {
      const int lo = number(part.substr(0, dash)), hi = number(part.substr(dash + 1));
      if (hi < lo || hi - lo > 1023) throw std::invalid_argument("--cpus " + text + ": bad range '" + part + "'");
      for (int c = lo; c <= hi; ++c) cpus.push_back(c);
    }
    if (comma == std::string::npos) break;
    pos = comma + 1;
  }
  return cpus;
}

}  // namespace evlife::engine
