// Warnings for the user made on a thread that must not print (the render
// thread, the replay's source thread) and said by the engine's monitor: a
// ring the maker writes (written_, release) and the monitor reads (read_,
// release once a slot is read); one made while the ring is full is counted.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

namespace evlife::engine {

template <typename T, std::size_t Slots = 16>
class NoticeRing {
 public:
  /// The maker's thread only; never blocks: the monitor is behind, counted.
  void put(const T& notice) noexcept {
    const std::uint64_t written = written_.load(std::memory_order_relaxed);
    if (written - read_.load(std::memory_order_acquire) >= Slots) {
      unsaid_.fetch_add(1, std::memory_order_relaxed);
      return;
    }
    slots_[written % Slots] = notice;
    written_.store(written + 1, std::memory_order_release);
  }

  /// The monitor's thread only: the oldest notice not taken, if any.
  std::optional<T> take() {
    const std::uint64_t read = read_.load(std::memory_order_relaxed);
    if (read == written_.load(std::memory_order_acquire)) return std::nullopt;
    std::optional<T> notice = slots_[read % Slots];
    read_.store(read + 1, std::memory_order_release);  // its slot may be written again
    return notice;
  }

  /// The monitor's thread only: the oldest notice as `text_of` words it;
  /// once none is left, how many a full ring lost ("N more `plural`, not
  /// said ..."); then empty.
  template <typename TextOf>
  std::string take_text(const TextOf& text_of, const char* plural) {
    if (const std::optional<T> notice = take()) return text_of(*notice);
    const std::uint64_t unsaid = unsaid_.exchange(0, std::memory_order_relaxed);
    return unsaid == 0 ? std::string{}
                       : std::to_string(unsaid) + " more " + plural +
                             ", not said (the warnings came faster than they were printed)";
  }

 private:
  std::array<T, Slots> slots_{};
  std::atomic<std::uint64_t> written_{0};
  std::atomic<std::uint64_t> read_{0};
  std::atomic<std::uint64_t> unsaid_{0};
};

}  // namespace evlife::engine
