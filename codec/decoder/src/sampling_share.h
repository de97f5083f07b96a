// SPDX-License-Identifier: MIT
// How much of a BrdfSampler table's draws go to cosine-weighted sampling. A table is a
// piecewise-constant fit of the BRDF's lobe; where the lobe is broad (a fabric or a matte paint
// near normal incidence) the fit's cell steps and the model's own error can give more variance
// than cosine-weighted sampling, whose weights f cos / pdf are then nearly flat. Each table's
// share c is chosen from the quadrature its masses were built from.
#pragma once

#include <span>

namespace cbrdf::internal {

// One quadrature point of a table's build: g = mean_rgb(f) cos(theta_i) at wi, the point's solid
// angle of wi (area of h times 4 wo.h), and its cell's index.
struct QuadraturePoint {
  double g;     // mean_rgb(f(wi, wo)) cos(theta_i), 0 where f is not positive or not finite
  double wi_z;  // cos(theta_i) > 0
  double d;     // wo . h > 0
  double area;  // the point's share of its cell's solid angle of h
  int cell;     // theta_h row * phi_h cells + phi_h column
};

// The share c in [c_min, 1] that minimises the predicted variance of f cos / pdf (the estimator
// of the albedo at the table's wo) under pdf = c cos / pi + (1 - c) table, to within 0.01; then 1
// (cosine-weighted only) unless the table's best is at least min_gain times less variance than
// cosine-weighted sampling's: the prediction is made on the tabulated BRDF (a model, which differs
// from the measurement it approximates by a few per cent), and a smaller predicted gain is within
// that error. table_pdf[k] is the table's density at points[k]'s wi; rejected holds the share of
// the table's mass that reflects below the horizon at other theta_o the table serves (its bin's
// edges): the variance predicted is the worst of these.
double best_cosine_share(std::span<const QuadraturePoint> points, std::span<const double> table_pdf,
                         std::span<const double> rejected, double c_min, double min_gain);

}  // namespace cbrdf::internal
