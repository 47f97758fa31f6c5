// Least-squares fit of a time plane dt = c + g . dp to window samples, with
// an optional prior on the gradient g (paper eq. 12). The offset c is
// eliminated by centring, leaving a 2 x 2 system in g.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "inlier_sums.h"
#include "window_samples.h"

namespace evlife::detail {

class PlaneFit {
 public:
  void add(double dx, double dy, double dt_us) noexcept { add_if(true, dx, dy, dt_us); }

  /// add(dx, dy, dt_us) when `take`, else adds +0 to every sum (which
  /// leaves them bit for bit as they are: none of them is ever -0).
  void add_if(bool take, double dx, double dy, double dt_us) noexcept {
    const double w = take ? 1.0 : 0.0;
    dx = take ? dx : 0.0;
    dy = take ? dy : 0.0;
    dt_us = take ? dt_us : 0.0;
    n_ += w;
    sx_ += dx;
    sy_ += dy;
    st_ += dt_us;
    sxx_ += dx * dx;
    sxy_ += dx * dy;
    syy_ += dy * dy;
    sxt_ += dx * dt_us;
    syt_ += dy * dt_us;
    stt_ += dt_us * dt_us;
  }

  /// Adds the samples of `nb` (pad() called) within sqrt(tol2_us2) of the
  /// plane dt = gx*dx + gy*dy, the test of WindowSamples::support(); the same
  /// sums bit for bit as add_if() over them in order. Fast path: the window's
  /// dx, dy are small integers and every dt an integer-valued float; with
  /// |dt| <= 2^21 us every partial sum is an integer below 2^53, exact in a
  /// double, so the sums can be taken four samples at a time in any order
  /// (and an exact sum is never -0, as add_if()'s never are).
  void add_inliers(const WindowSamples& nb, float gx, float gy, float tol2_us2) noexcept {
    InlierSums s;
    if (!exact_inlier_sums(nb, gx, gy, tol2_us2, s)) {
      for (int k = 0; k < nb.count; ++k) {
        const float r = nb.dt_us[k] - gx * nb.dx[k] - gy * nb.dy[k];
        add_if(r * r <= tol2_us2, static_cast<double>(nb.dx[k]), static_cast<double>(nb.dy[k]),
               static_cast<double>(nb.dt_us[k]));
      }
      return;
    }
    n_ += s.n;
    sx_ += s.sx;
    sy_ += s.sy;
    st_ += s.st;
    sxx_ += s.sxx;
    sxy_ += s.sxy;
    syy_ += s.syy;
    sxt_ += s.sxt;
    syt_ += s.syt;
    stt_ += s.stt;
  }

  /// Root mean square residual of the samples about dt = c + g . dp, with c
  /// chosen best for g; per degree of freedom (n - 3). -1 with n <= 3.
  double residual_rms(const Eigen::Vector2d& g) const noexcept {
    if (n_ <= 3.0) return -1.0;
    // sum (t - g.p)^2 - (sum (t - g.p))^2 / n, expanded in the sums.
    const double gx = g.x(), gy = g.y();
    const double s1 = st_ - gx * sx_ - gy * sy_;
    const double s2 = stt_ - 2.0 * (gx * sxt_ + gy * syt_) + gx * gx * sxx_ + 2.0 * gx * gy * sxy_ + gy * gy * syy_;
    const double sse = s2 - s1 * s1 / n_;
    return std::sqrt(std::max(sse, 0.0) / (n_ - 3.0));
  }

  /// True when the standard error of the lifetime |g| of a solve()d gradient
  /// g is at most max_share x |g|, when max_share <= 0 (no check), or when it
  /// cannot be told (rms < 0: n <= 3; such fits continue an edge upstream). The
  /// standard error is rms x sqrt(u^T A^-1 u), from the residual RMS about
  /// the fit (residual_rms(g)) and the samples' spread along g (A: the
  /// centred scatter matrix + lambda I, u = g / |g|); compared squared and
  /// multiplied out (A^-1 = adj(A) / det(A), det(A) > 0 after solve()): no
  /// root or division per event.
  bool lifetime_within(const Eigen::Vector2d& g, double lambda, double rms, double max_share) const noexcept {
    if (max_share <= 0.0 || rms < 0.0) return true;
    const Eigen::Matrix2d a = centred_scatter(lambda, n_);
    const double gx = g.x(), gy = g.y();
    const double g_adj_g = gx * gx * a(1, 1) - 2.0 * gx * gy * a(0, 1) + gy * gy * a(0, 0);
    const double g2 = gx * gx + gy * gy;
    return rms * rms * g_adj_g <= max_share * max_share * g2 * g2 * a.determinant();
  }

  /// The offset c at the first sample added (the anchor, add()ed at the
  /// origin) of the plane fitted to the other samples alone: minimizes
  /// sum (dt - c - g.dp)^2 + lambda |g - prior|^2 over them. False when they
  /// are fewer than 3 or do not determine g.
  bool offset_without_anchor(double lambda, const Eigen::Vector2d& prior, double& c) const noexcept {
    const double n = n_ - 1.0;  // the anchor adds 1 to n and 0 to every other sum
    Eigen::Vector2d g;
    if (n < 3.0 || !solve_over(n, lambda, prior, g)) return false;
    c = (st_ - g.x() * sx_ - g.y() * sy_) / n;
    return true;
  }

  /// Minimizes sum (dt - c - g.dp)^2 + lambda |g - prior|^2 over (c, g).
  /// Returns false when the samples do not determine g (collinear, no prior).
  bool solve(double lambda, const Eigen::Vector2d& prior, Eigen::Vector2d& g) const noexcept {
    return n_ >= 1.0 && solve_over(n_, lambda, prior, g);
  }

 private:
  // solve() over n of the samples: all (n_), or all but the anchor (n_ - 1).
  bool solve_over(double n, double lambda, const Eigen::Vector2d& prior, Eigen::Vector2d& g) const noexcept {
    const Eigen::Matrix2d a = centred_scatter(lambda, n);
    const Eigen::Vector2d b(sxt_ - sx_ * st_ / n + lambda * prior.x(), syt_ - sy_ * st_ / n + lambda * prior.y());
    const double det = a.determinant();
    // Relative to the trace: below this the spatial spread is a line.
    if (!(det > 1e-9 * a.trace() * a.trace())) return false;
    g = a.inverse() * b;
    return true;
  }

  // The samples' spatial scatter about their mean, plus lambda I (the prior).
  Eigen::Matrix2d centred_scatter(double lambda, double n) const noexcept {
    Eigen::Matrix2d a;
    a << sxx_ - sx_ * sx_ / n + lambda, sxy_ - sx_ * sy_ / n,  //
        sxy_ - sx_ * sy_ / n, syy_ - sy_ * sy_ / n + lambda;
    return a;
  }

  double n_ = 0, sx_ = 0, sy_ = 0, st_ = 0, sxx_ = 0, sxy_ = 0, syy_ = 0, sxt_ = 0, syt_ = 0, stt_ = 0;
};

}  // namespace evlife::detail
