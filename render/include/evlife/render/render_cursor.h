// Walks an AugmentedSource forward in time, feeding the active-event set and
// the fixed-window map, so frames can be drawn at increasing instants
// without re-reading the recording: advancing from t1 to t2 costs only the
// events in (t1, t2]. Times here are absolute (the recording's clock).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "evlife/algo/active_event_map.h"
#include "evlife/render/augmented_source.h"
#include "evlife/render/fixed_window_map.h"

namespace evlife::render {

class RenderCursor {
 public:
  /// `window` may be null when no fixed window is drawn. The buffer holds at
  /// least 2 events (read_past_next keeps one and reads behind it).
  RenderCursor(AugmentedSource& source, ActiveEventMap& set, FixedWindowMap* window,
               std::size_t buffer_events = 8192);

  /// Timestamp of the first event (reads ahead); nullopt for an empty source.
  std::optional<std::int64_t> first_t_us();

  /// Feeds every event with t <= t_us. Times must not decrease between
  /// calls (std::invalid_argument otherwise: reset the set and open a new
  /// cursor to go back). Read errors of the source propagate.
  void advance_to(std::int64_t t_us);

  /// True once the source is exhausted and every event was fed.
  bool exhausted() const noexcept { return ended_ && pos_ == count_; }
  /// Time of the next event after the cursor when it is read already (after
  /// advance_to, unless the source ended): what a frame rate has ahead.
  std::optional<std::int64_t> next_t_us() const noexcept {
    return pos_ < count_ ? std::optional<std::int64_t>(buffer_[pos_].event.t_us) : std::nullopt;
  }
  /// Reads the event after the next one when it is not read yet, so that a
  /// read error right after the cursor is raised, not left unread: a time
  /// that a corrupt record made jump ahead stops advance_to like a later
  /// event would, and only its successor, going back, shows the fault (the
  /// frames before it lack the events behind it). Read errors propagate.
  void read_past_next();
  /// Time of the latest event fed (INT64_MIN before the first).
  std::int64_t last_fed_t_us() const noexcept { return last_fed_t_us_; }
  std::uint64_t events_fed() const noexcept { return events_fed_; }
  std::int64_t cursor_t_us() const noexcept { return cursor_t_us_; }

 private:
  bool refill();

  AugmentedSource& source_;
  ActiveEventMap& set_;
  FixedWindowMap* window_;
  std::vector<AugmentedEvent> buffer_;
  std::size_t pos_ = 0;
  std::size_t count_ = 0;
  bool ended_ = false;
  std::int64_t cursor_t_us_ = INT64_MIN;
  std::int64_t last_fed_t_us_ = INT64_MIN;
  std::uint64_t events_fed_ = 0;
};

}  // namespace evlife::render
