// SPDX-License-Identifier: MIT
// Microfacet building blocks shared by the analytic lobes (and checked directly by the tests).
// Angles are passed as tangent squared or cosine so that callers can compute them without the
// cancellation of 1 - cos^2 near the normal.
#pragma once

#include <cmath>
#include <numbers>

namespace cbrdf::internal {

// GGX (Trowbridge-Reitz) normal distribution at a half vector with cos(theta_h) = cos_h and
// tan^2(theta_h) = tan2_h; normalized so that the integral of D cos(theta_h) over the hemisphere
// is 1.
inline double ggx_d(double alpha, double cos_h, double tan2_h) {
  const double a2 = alpha * alpha;
  const double c2 = cos_h * cos_h;
  const double k = 1.0 + tan2_h / a2;
  return 1.0 / (std::numbers::pi * a2 * c2 * c2 * k * k);
}

// Beckmann distribution (the Ward lobe's), with the same normalization as ggx_d.
inline double beckmann_d(double alpha, double cos_h, double tan2_h) {
  const double a2 = alpha * alpha;
  const double c2 = cos_h * cos_h;
  return std::exp(-tan2_h / a2) / (std::numbers::pi * a2 * c2 * c2);
}

// Smith Lambda for GGX at a direction with tan^2(theta) = tan2. Written as x / (2 (sqrt(1 + x) +
// 1)) rather than (sqrt(1 + x) - 1) / 2 so that small roughness keeps full precision.
inline double ggx_lambda(double alpha, double tan2) {
  const double x = alpha * alpha * tan2;
  return x / (2.0 * (std::sqrt(1.0 + x) + 1.0));
}

// Smith masking of one direction (the microfacet's back-facing test is the caller's).
inline double ggx_g1(double alpha, double tan2) {
  return 1.0 / (1.0 + ggx_lambda(alpha, tan2));
}

// Height-correlated Smith masking-shadowing (Heitz 2014); symmetric in its two directions.
inline double ggx_g2(double alpha, double tan2_i, double tan2_o) {
  return 1.0 / (1.0 + (ggx_lambda(alpha, tan2_i) + ggx_lambda(alpha, tan2_o)));
}

// Schlick's Fresnel approximation at cos of the angle between the light and the microfacet normal.
inline double schlick(double f0, double cos_d) {
  const double m = 1.0 - cos_d;
  const double m2 = m * m;
  return f0 + (1.0 - f0) * m2 * m2 * m;
}

}  // namespace cbrdf::internal
