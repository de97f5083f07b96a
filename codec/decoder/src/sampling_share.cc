// SPDX-License-Identifier: MIT
#include "sampling_share.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "sampling_math.h"

namespace cbrdf::internal {

namespace {

// The points that carry part of the integrand, as the terms of E[(f cos / pdf)^2] under the
// mixture with share c: sum of w / (c b + (1 - c) t), w = g^2 times the point's solid angle, b the
// cosine's density and t the table's. Arrays, so that the sum vectorizes.
struct Terms {
  std::vector<double> w, b, t;
  bool table_misses = false;  // the table's density is 0 where the integrand is not
};

Terms terms_of(std::span<const QuadraturePoint> points, std::span<const double> table_pdf) {
  Terms terms;
  for (std::size_t k = 0; k < points.size(); ++k) {
    const QuadraturePoint& q = points[k];
    if (!(q.g > 0)) continue;
    terms.w.push_back(q.g * q.g * (q.area * 4 * q.d));
    terms.b.push_back(q.wi_z / kPi);
    terms.t.push_back(table_pdf[k]);
    terms.table_misses = terms.table_misses || !(table_pdf[k] > 0);
  }
  return terms;
}

// E[(f cos / pdf)^2] - A^2 under the mixture with share c, by the points' quadrature; infinite
// where the mixture misses a point that carries part of the integrand.
double predicted_variance(const Terms& terms, double c, double albedo) {
  if (terms.table_misses && !(c > 0)) return std::numeric_limits<double>::infinity();
  double second = 0.0;
  const std::size_t n = terms.w.size();
  for (std::size_t k = 0; k < n; ++k) {
    second += terms.w[k] / (c * terms.b[k] + (1 - c) * terms.t[k]);
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
  const Terms terms = terms_of(points, table_pdf);
  const double a2 = albedo * albedo;
  // The worst over the bin: at another theta_o a share R of the table's mass reflects below the
  // horizon, and those draws score 0 while the rest carry the whole mean (to first order the
  // valid draws' density shrinks by 1 - (1 - c) R).
  const auto worst = [&](double c) {
    const double v = predicted_variance(terms, c, albedo);
    double w = v;
    for (double r : rejected) {
      const double kept = 1 - (1 - c) * std::clamp(r, 0.0, 1.0);
      w = std::max(w, kept > 0 ? (v + a2) / kept - a2 : std::numeric_limits<double>::infinity());
    }
    return w;
  };
  // A golden-section search over [c_min, 1] (the second moment is convex in c), to within 0.01,
  // and the ends.
  constexpr double kGolden = 0.6180339887498949;
  double lo = c_min, hi = 1.0;
  double x1 = hi - kGolden * (hi - lo), x2 = lo + kGolden * (hi - lo);
  double f1 = worst(x1), f2 = worst(x2);
  while (hi - lo > 0.01) {
    if (f1 < f2) {
      hi = x2;
      x2 = x1;
      f2 = f1;
      x1 = hi - kGolden * (hi - lo);
      f1 = worst(x1);
    } else {
      lo = x1;
      x1 = x2;
      f1 = f2;
      x2 = lo + kGolden * (hi - lo);
      f2 = worst(x2);
    }
  }
  const double cosine = worst(1.0);
  double best_c = 1.0, best = cosine;
  for (const auto& [c, v] :
       {std::pair{c_min, worst(c_min)}, std::pair{x1, f1}, std::pair{x2, f2}}) {
    if (v < best) {
      best = v;
      best_c = c;
    }
  }
  // best <= cosine; the gain test is written so that best = 0 passes and cosine = 0 does not.
  return best * min_gain <= cosine && best < cosine ? best_c : 1.0;
}

}  // namespace cbrdf::internal
