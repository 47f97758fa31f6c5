#include "evlife/algo/active_event_map.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace evlife {

namespace {
// sin(22.5 deg): a unit velocity component above this points at that
// neighbour, so the 8 neighbours each cover a 45 degree sector.
constexpr float kSectorSin = 0.38268343f;
}  // namespace

ActiveEventMap::ActiveEventMap(SensorSize sensor, bool edge_thinning)
    : sensor_(sensor), edge_thinning_(edge_thinning) {
  if (!fits(sensor)) {
#if defined(__cpp_exceptions)
    throw std::invalid_argument("ActiveEventMap: sensor size " + std::to_string(sensor.width) +
                                "x" + std::to_string(sensor.height) + " out of range 1.." +
                                std::to_string(kMaxSide) + " each way");
#else
    std::abort();  // built without exceptions: check ActiveEventMap::fits() first
#endif
  }
  const auto n = static_cast<std::size_t>(sensor.pixel_count());
  expire_rel_.assign(n, kNeverRel);
  t_us_.assign(n, kNever);
  lifetime_us_.assign(n, 0.0f);
  vx_px_s_.assign(n, 0.0f);
  vy_px_s_.assign(n, 0.0f);
  polarity_.assign(n, 0);
}

void ActiveEventMap::reset() noexcept {
  std::fill(expire_rel_.begin(), expire_rel_.end(), kNeverRel);
  epoch_us_ = 0;
  has_epoch_ = false;
  std::fill(t_us_.begin(), t_us_.end(), kNever);
  std::fill(lifetime_us_.begin(), lifetime_us_.end(), 0.0f);
  std::fill(vx_px_s_.begin(), vx_px_s_.end(), 0.0f);
  std::fill(vy_px_s_.begin(), vy_px_s_.end(), 0.0f);
  std::fill(polarity_.begin(), polarity_.end(), std::int8_t{0});
  last_fed_t_us_ = kNever;
  stats_ = {};
}

void ActiveEventMap::feed(const AugmentedEvent& a) noexcept {
  ++stats_.fed;
  const Event& e = a.event;
  if (!sensor_.value.contains(e.x, e.y)) {
    ++stats_.out_of_sensor;
    return;
  }
  if (!within_event_time_range(e.t_us)) {
    ++stats_.time_out_of_range;
    return;
  }
  last_fed_t_us_ = std::max(last_fed_t_us_, e.t_us);
  // NaN compares false, so !(> 0) also rejects a NaN lifetime.
  if (!(a.lifetime_us > 0.0f)) {
    ++stats_.noise;
    return;
  }
  const std::size_t i = index(e.x, e.y);
  if (e.t_us < t_us_[i]) {
    ++stats_.late;
    return;
  }
  // Times up to 2^63 apart (event.h's range, both ends): t - epoch taken
  // without overflow (it was signed overflow, and a valid event counted late).
  std::int64_t since_epoch = 0;
  const bool far = __builtin_sub_overflow(e.t_us, epoch_us_, &since_epoch);
  if (!has_epoch_ || (far ? e.t_us > epoch_us_ : since_epoch > kMaxRel - kMaxLifetimeUs)) {
    rebase(e.t_us);
  } else if (far || since_epoch <= kNeverRel) {  // before the 32-bit range: its expiry would wrap
    ++stats_.late;
    return;
  }
  // Active while t - t_event < lifetime; with integer t that is t < t_event + ceil(lifetime).
  const double lifetime = std::min(static_cast<double>(a.lifetime_us), static_cast<double>(kMaxLifetimeUs));
  expire_rel_[i] = static_cast<std::int32_t>(e.t_us - epoch_us_ + static_cast<std::int64_t>(std::ceil(lifetime)));
  t_us_[i] = e.t_us;
  lifetime_us_[i] = a.lifetime_us;
  vx_px_s_[i] = a.vx_px_s;
  vy_px_s_[i] = a.vy_px_s;
  polarity_[i] = e.p;
  ++stats_.stored;

  if (!edge_thinning_) return;
  const float speed = std::hypot(a.vx_px_s, a.vy_px_s);
  if (!(speed > 0.0f) || !std::isfinite(speed)) return;
  const float ux = a.vx_px_s / speed;
  const float uy = a.vy_px_s / speed;
  const int dx = ux > kSectorSin ? 1 : (ux < -kSectorSin ? -1 : 0);
  const int dy = uy > kSectorSin ? 1 : (uy < -kSectorSin ? -1 : 0);
  const int nx = e.x - dx;  // the pixel the edge has just left
  const int ny = e.y - dy;
  if (!sensor_.value.contains(nx, ny)) return;
  const std::size_t j = index(nx, ny);
  const std::int32_t now_rel = static_cast<std::int32_t>(e.t_us - epoch_us_);
  if (polarity_[j] == e.p && t_us_[j] < e.t_us && expire_rel_[j] > now_rel) {
    expire_rel_[j] = now_rel;
    ++stats_.thinned;
  }
}

std::size_t ActiveEventMap::count_active(std::int64_t t_us) const noexcept {
  const std::int64_t rel = relative_time(t_us);
  std::size_t n = 0;
  for (const std::int32_t expire : expire_rel_) n += rel < expire ? 1u : 0u;
  return n;
}

std::size_t ActiveEventMap::active_pixels(std::int64_t t_us, std::span<ActivePixel> out) const noexcept {
  const std::int64_t rel = relative_time(t_us);
  const auto width = static_cast<std::size_t>(sensor_.value.width);
  std::size_t n = 0;
  for (std::size_t i = 0; i < expire_rel_.size(); ++i) {
    if (!(rel < expire_rel_[i])) continue;
    if (n < out.size()) {
      out[n] = ActivePixel{t_us_[i], static_cast<std::uint16_t>(i % width),
                           static_cast<std::uint16_t>(i / width), polarity_[i],
                           lifetime_us_[i], vx_px_s_[i], vy_px_s_[i]};
    }
    ++n;
  }
  return n;
}

void ActiveEventMap::lifetime_image(std::int64_t t_us, std::span<float> out) const noexcept {
  const std::int64_t rel = relative_time(t_us);
  const std::size_t n = std::min(out.size(), expire_rel_.size());
  for (std::size_t i = 0; i < n; ++i) out[i] = rel < expire_rel_[i] ? lifetime_us_[i] : 0.0f;
}

// Moves the epoch so that t_us sits near the start of the int32 range:
// O(sensor), once per ~9 minutes of recording (never on a typical frame).
void ActiveEventMap::rebase(std::int64_t t_us) noexcept {
  const std::int64_t new_epoch = t_us - kMaxLifetimeUs;
  if (has_epoch_) {
    // Forward only (feed() rebases for a later time); beyond 2^40 us every
    // stored expiry ends as the exact shift would end it, and nothing overflows.
    constexpr std::int64_t kShiftBound = std::int64_t{1} << 40;
    std::int64_t shift = 0;
    if (__builtin_sub_overflow(new_epoch, epoch_us_, &shift) || shift > kShiftBound) shift = kShiftBound;
    for (std::int32_t& e : expire_rel_) {
      if (e == kNeverRel) continue;
      const std::int64_t moved = static_cast<std::int64_t>(e) - shift;
      e = moved <= kNeverRel ? kNeverRel : static_cast<std::int32_t>(moved);
    }
  }
  epoch_us_ = new_epoch;
  has_epoch_ = true;
}

}  // namespace evlife
