#include "evlife/algo/lifetime_estimator.h"

#include <Eigen/Core>
#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "event_rng.h"

namespace evlife {
namespace {

constexpr std::int64_t kNeverFired = std::numeric_limits<std::int64_t>::min();
constexpr int kMaxWindowSide = 15;
constexpr int kMaxNeighbours = kMaxWindowSide * kMaxWindowSide - 1;

// A past event in the window, relative to the new event: (dx, dy) px, dt us (<= 0).
struct Neighbour {
  float dx;
  float dy;
  float dt_us;
};

int ransac_iterations_for(double outlier_fraction, double confidence) {
  const double inlier_pair = (1.0 - outlier_fraction) * (1.0 - outlier_fraction);
  const double k = std::log(1.0 - confidence) / std::log(1.0 - inlier_pair);
  return std::max(1, static_cast<int>(std::ceil(k)));
}

}  // namespace

LifetimeEstimator::LifetimeEstimator(const LifetimeOptions& options) : options_(options) {
  if (const std::string err = validate_lifetime_options(options); !err.empty()) {
    throw std::invalid_argument("LifetimeOptions." + err);
  }
  half_window_ = options_.window_size / 2;
  ransac_iterations_ = ransac_iterations_for(options_.outlier_fraction, options_.ransac_confidence);
  min_support_fraction_ = 1.0 - options_.outlier_fraction;
  states_.resize(2 * static_cast<std::size_t>(options_.sensor.pixel_count()));
  reset();
}

void LifetimeEstimator::reset() noexcept {
  std::fill(states_.begin(), states_.end(), PixelState{kNeverFired, 0, 0.0f, 0.0f, false});
  stats_ = LifetimeStats{};
}

std::size_t LifetimeEstimator::process(std::span<const Event> in,
                                       std::span<AugmentedEvent> out) noexcept {
  const std::size_t n = std::min(in.size(), out.size());
  for (std::size_t i = 0; i < n; ++i) out[i] = process(in[i]);
  return n;
}

AugmentedEvent LifetimeEstimator::process(const Event& e) noexcept {
  AugmentedEvent out;
  out.event = e;
  ++stats_.events;
  const int W = options_.sensor.width;
  const int H = options_.sensor.height;
  if (e.x >= W || e.y >= H) {
    ++stats_.out_of_sensor;
    ++stats_.noise;
    return out;
  }
  if (e.p != 1 && e.p != -1) {
    ++stats_.bad_polarity;
    ++stats_.noise;
    return out;
  }
  const int pol = e.p > 0 ? 1 : 0;
  const int x = e.x;
  const int y = e.y;
  PixelState& self = state(pol, x, y);

  // Prediction for this pixel made by an earlier event (paper III-B.2).
  bool use_prior = false;
  float prior_gx = 0.0f, prior_gy = 0.0f;
  double lambda = 0.0;
  if (self.has_prediction) {
    const double err_us = static_cast<double>(e.t_us - self.predicted_t_us);
    out.prediction_error_us = static_cast<float>(err_us);
    ++stats_.predictions;
    if (options_.regularization) {
      use_prior = true;
      prior_gx = self.predicted_gx_us_px;
      prior_gy = self.predicted_gy_us_px;
      lambda = options_.lambda_offset +
               options_.lambda_gain * std::exp(-options_.lambda_decay_per_us * std::fabs(err_us));
    }
    self.has_prediction = false;
  }

  // Gather the window's past events (the part of the window inside the sensor).
  const int x0 = std::max(0, x - half_window_), x1 = std::min(W - 1, x + half_window_);
  const int y0 = std::max(0, y - half_window_), y1 = std::min(H - 1, y + half_window_);
  const int window_pixels = (x1 - x0 + 1) * (y1 - y0 + 1);
  Neighbour nb[kMaxNeighbours];
  int count = 0;
  for (int yy = y0; yy <= y1; ++yy) {
    const PixelState* row = &state(pol, 0, yy);
    for (int xx = x0; xx <= x1; ++xx) {
      const std::int64_t t = row[xx].last_t_us;
      if (t == kNeverFired || t > e.t_us || (xx == x && yy == y)) continue;
      nb[count++] = {static_cast<float>(xx - x), static_cast<float>(yy - y),
                     static_cast<float>(t - e.t_us)};
    }
  }
  self.last_t_us = e.t_us;

  // Only the newer half of the window (paper Fig. 6): older events belong to
  // an earlier edge, newer ones do not exist yet.
  const int half = (window_pixels - 1) / 2;
  if (count > half) {
    std::nth_element(nb, nb + half, nb + count,
                     [](const Neighbour& a, const Neighbour& b) { return a.dt_us > b.dt_us; });
    count = half;
  }
  // Minimum support m = (1 - eps) * N^2 / 2 (eq. 8), counting the new event,
  // scaled to the part of the window inside the sensor.
  const int min_support =
      std::max(3, static_cast<int>(std::ceil(min_support_fraction_ * window_pixels * 0.5 - 1e-9)));
  if (count + 1 < min_support) {
    ++stats_.noise;
    return out;
  }

  // RANSAC: candidate planes dt = gx*dx + gy*dy through the new event and two
  // sampled past events; support = past events within the time tolerance.
  const float tol = static_cast<float>(options_.inlier_tolerance_us);
  detail::EventRng rng(options_.seed, e);
  int best_support = 0;
  float best_gx = 0.0f, best_gy = 0.0f;
  for (int it = 0; it < ransac_iterations_; ++it) {
    const std::uint32_t i = rng.below(static_cast<std::uint32_t>(count));
    std::uint32_t j = rng.below(static_cast<std::uint32_t>(count - 1));
    if (j >= i) ++j;
    const Neighbour& a = nb[i];
    const Neighbour& b = nb[j];
    const float det = a.dx * b.dy - b.dx * a.dy;
    if (std::fabs(det) < 0.5f) continue;  // collinear with the new event
    const float gx = (a.dt_us * b.dy - b.dt_us * a.dy) / det;
    const float gy = (a.dx * b.dt_us - b.dx * a.dt_us) / det;
    int support = 1;  // the new event
    for (int k = 0; k < count; ++k) {
      support += std::fabs(nb[k].dt_us - gx * nb[k].dx - gy * nb[k].dy) <= tol;
    }
    if (support > best_support) {
      best_support = support;
      best_gx = gx;
      best_gy = gy;
    }
  }
  if (best_support < min_support) {
    ++stats_.noise;
    return out;
  }

  // Least-squares refit on the inliers and the new event: dt = c + g . dp,
  // regularized towards the predicted gradient (eq. 12).
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  normal(0, 0) = 1.0;  // the new event at (0, 0, 0)
  for (int k = 0; k < count; ++k) {
    const Neighbour& n = nb[k];
    if (std::fabs(n.dt_us - best_gx * n.dx - best_gy * n.dy) > tol) continue;
    const Eigen::Vector3d row(1.0, n.dx, n.dy);
    normal.noalias() += row * row.transpose();
    rhs.noalias() += row * static_cast<double>(n.dt_us);
  }
  if (use_prior) {
    normal(1, 1) += lambda;
    normal(2, 2) += lambda;
    rhs(1) += lambda * static_cast<double>(prior_gx);
    rhs(2) += lambda * static_cast<double>(prior_gy);
  }
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(normal);
  const Eigen::Vector3d sol = ldlt.solve(rhs);
  const double gx = sol(1), gy = sol(2);
  const double g2 = gx * gx + gy * gy;
  const double lifetime_us = std::sqrt(g2);
  if (ldlt.info() != Eigen::Success || !std::isfinite(lifetime_us) || lifetime_us <= 0.0 ||
      lifetime_us > options_.max_lifetime_us) {
    ++stats_.noise;
    return out;
  }

  out.lifetime_us = static_cast<float>(lifetime_us);
  out.vx_px_s = static_cast<float>(gx / g2 * 1e6);
  out.vy_px_s = static_cast<float>(gy / g2 * 1e6);

  // Predict the next event at the neighbour in the direction of motion (the
  // SAE rises along the motion, so along +grad).
  const int qx = x + static_cast<int>(std::lround(gx / lifetime_us));
  const int qy = y + static_cast<int>(std::lround(gy / lifetime_us));
  if (qx >= 0 && qy >= 0 && qx < W && qy < H && (qx != x || qy != y)) {
    PixelState& q = state(pol, qx, qy);
    q.predicted_t_us = e.t_us + std::llround(gx * (qx - x) + gy * (qy - y));
    q.predicted_gx_us_px = static_cast<float>(gx);
    q.predicted_gy_us_px = static_cast<float>(gy);
    q.has_prediction = true;
  }
  return out;
}

}  // namespace evlife
