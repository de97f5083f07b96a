// SPDX-License-Identifier: MIT
// Fast evaluation of the 3-D Frank copula density over a tensor grid, for fitting and
// reconstruction.
//
// Paper convention: alpha, with the standard Frank parameter t = -alpha. With b = 1 - e^{-t} and
// per axis e = e^{-t u}, w = (1 - e^{-t u}) / b, y = 1 - w = (e^{-t u} - e^{-t}) / b, the density
// is
//   c = (t / b)^2 * e1 e2 e3 * (1 + h) / (1 - h)^3,   h = b w1 w2 w3,
// and 1 - h, 1 + h are formed without cancellation, using 1 - w1 w2 w3 = y1 + w1 y2 + w1 w2 y3:
//   t > 0:  1 - h = e^{-t} + b (y1 + w1 y2 + w1 w2 y3),  1 + h = 1 + b w1 w2 w3  (terms >= 0)
//   t < 0:  1 - h = 1 - b w1 w2 w3,  1 + h = (2 - e^{-t}) - b (y1 + w1 y2 + w1 w2 y3)
// (b < 0 there, and 2 - e^{-t} >= 0 is exactly the domain alpha <= ln 2: the density's zero at the
// domain's edge is then computed to full relative accuracy.)
// Per axis the terms are computed with expm1, so a bin costs a few multiply-adds and one division.
// Valid for -200 <= alpha <= ln 2: beyond alpha = -200 the factor e1 e2 e3 can underflow; the
// fitter bounds alpha there (copula.h evaluates the whole domain in the log domain).
#pragma once

#include <cmath>
#include <vector>

namespace cbrdf::internal {

inline constexpr double kFrankGridMinAlpha = -200.0;

struct FrankAxis {
  std::vector<double> e, w, y, q;  // q = u / expm1(t u), for d log h / dt
  std::vector<double> u;
};

class FrankGrid {
 public:
  // Prepares per-axis terms for CDF values u1 (theta_h), u2 (theta_d), u3 (phi_d) at alpha.
  void prepare(double alpha, const std::vector<double>& u1, const std::vector<double>& u2,
               const std::vector<double>& u3);

  double alpha() const { return alpha_; }

  // Density at grid point (i, j, k).
  double density(int i, int j, int k) const {
    if (t_ == 0.0) return 1.0;
    const double w1 = ax_[0].w[i], w2 = ax_[1].w[j], w3 = ax_[2].w[k];
    double omh, oph;
    terms(i, j, k, w1, w2, w3, &omh, &oph);
    return k2_ * ax_[0].e[i] * ax_[1].e[j] * ax_[2].e[k] * oph / (omh * omh * omh);
  }

  // Density and its derivative with respect to alpha at (i, j, k).
  double density_and_derivative(int i, int j, int k, double* dc_dalpha) const;

  // The densities (and derivatives, when dc is not null) of a whole phi_d row (i, j, k = 0..n3-1):
  // the per-row factors are formed once and the inner loop vectorizes.
  void row(int i, int j, double* c, double* dc) const;

 private:
  void prepare_axis(const std::vector<double>& u, FrankAxis* axis) const;
  // 1 - h and 1 + h for h = b w1 w2 w3 (see the header comment).
  void terms(int i, int j, int k, double w1, double w2, double w3, double* omh, double* oph) const {
    const double one_minus_w = ax_[0].y[i] + w1 * ax_[1].y[j] + w1 * w2 * ax_[2].y[k];
    if (t_ > 0) {
      *omh = et_ + b_ * one_minus_w;
      *oph = 1.0 + b_ * w1 * w2 * w3;
    } else {
      *omh = 1.0 - b_ * w1 * w2 * w3;
      *oph = one_plus_b_ - b_ * one_minus_w;
    }
  }

  double alpha_ = 0, t_ = 0, b_ = 0, et_ = 1, one_plus_b_ = 1, k2_ = 1, d0_ = 1, q1_ = 0;
  FrankAxis ax_[3];
};

}  // namespace cbrdf::internal
