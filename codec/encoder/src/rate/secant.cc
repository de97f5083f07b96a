// SPDX-License-Identifier: MIT
#include "rate/secant.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cbrdf::internal {

Secant::Secant(double x_min, double x_max, double slope)
    : x_min_(x_min), x_max_(x_max), slope_(slope) {}

void Secant::add(double x, double value, bool met) {
  points_.push_back({x, value, met});
}

std::optional<Secant::Point> Secant::nearest(bool met) const {
  // The value falls with x: the met tries lie on one side of the crossing, the missed ones on the
  // other; the nearest of each kind is the one closest to a try of the other.
  std::optional<Point> best;
  double best_d = 0;
  for (const Point& p : points_) {
    if (p.met != met) continue;
    double d = std::numeric_limits<double>::infinity();
    for (const Point& q : points_) {
      if (q.met != met) d = std::min(d, std::abs(p.x - q.x));
    }
    if (!best || d < best_d) best = p, best_d = d;
  }
  return best;
}

std::optional<double> Secant::next(double aim) const {
  if (points_.empty()) return std::nullopt;
  const Point& last = points_.back();
  double slope = slope_;
  if (points_.size() >= 2) {
    const Point& prev = points_[points_.size() - 2];
    const double s = (last.value - prev.value) / (last.x - prev.x);
    if (std::isfinite(s) && s < 0) slope = s;  // the value falls with x: else noise
  }
  // A step of the secant, at most 3 (a factor of 20 in E) while nothing brackets the crossing.
  double x = last.x + std::clamp((aim - last.value) / slope, -3.0, 3.0);
  x = std::clamp(x, x_min_, x_max_);
  const std::optional<Point> met = nearest(true), missed = nearest(false);
  if (met && missed) {
    const double lo = std::min(met->x, missed->x), hi = std::max(met->x, missed->x);
    if (hi - lo < kClose) return std::nullopt;
    // Inside the bracket, away from its ends (else the secant creeps along one side).
    const double margin = 0.1 * (hi - lo);
    if (!(x > lo + margin && x < hi - margin)) x = 0.5 * (lo + hi);
  }
  for (const Point& p : points_) {
    if (std::abs(p.x - x) < 0.5 * kClose) return std::nullopt;  // the end of the range, again
  }
  return x;
}

}  // namespace cbrdf::internal
