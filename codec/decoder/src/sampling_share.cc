// SPDX-License-Identifier: MIT
#include "sampling_share.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sampling_math.h"

namespace cbrdf::internal {

namespace {

// E[(f cos / pdf)^2] - A^2 under the mixture with share c, by the points' quadrature; infinite
// where the mixture misses a point that carries part of the integrand.
double predicted_variance(std::span<const QuadraturePoint> points,
                          std::span<const double> table_pdf, double c, double albedo) {
  double second = 0.0;
  for (std::size_t k = 0; k < points.size(); ++k) {
    const QuadraturePoint& q = points[k];
    if (!(q.g > 0)) continue;
    const double pdf = c * q.wi_z / kPi + (1 - c) * table_pdf[k];
    if (!(pdf > 0)) return std::numeric_limits<double>::infinity();
    second += q.g * q.g / pdf * (q.area * 4 * q.d);
  }
  return std::max(0.0, second - albedo * albedo);
}

}  // namespace

double best_cosine_share(std::span<const QuadraturePoint> points, std::span<const double> table_pdf,
                         std::span<const double> rejected, double c_min, double min_gain) {
  if (!(min_gain > 0)) return c_min;
  double albedo = 0.0;
  for (const QuadraturePoint& q : points) albedo += q.g * q.area * 4 * q.d;
  if (!(albedo > 0) || !std::isfinite(albedo)) return 1.0;
  const double a2 = albedo * albedo;
  // The worst over the bin: at another theta_o a share R of the table's mass reflects below the
  // horizon, and those draws score 0 while the rest carry the whole mean (to first order the
  // valid draws' density shrinks by 1 - (1 - c) R).
  const auto worst = [&](double c) {
    const double v = predicted_variance(points, table_pdf, c, albedo);
    double w = v;
    for (double r : rejected) {
      const double kept = 1 - (1 - c) * std::clamp(r, 0.0, 1.0);
      w = std::max(w, kept > 0 ? (v + a2) / kept - a2 : std::numeric_limits<double>::infinity());
    }
    return w;
  };
  constexpr int kSteps = 40;
  double best_c = 1.0;
  const double cosine = worst(1.0);
  double best = cosine;
  for (int i = 0; i < kSteps; ++i) {
    const double c = c_min + (1 - c_min) * i / kSteps;
    const double v = worst(c);
    if (v < best) {
      best = v;
      best_c = c;
    }
  }
  // best <= cosine; the gain test is written so that best = 0 passes and cosine = 0 does not.
  return best * min_gain <= cosine && best < cosine ? best_c : 1.0;
}

}  // namespace cbrdf::internal
