// SPDX-License-Identifier: MIT
// directional_albedo(): quadrature over half vectors (wi = reflect(wo, h), d(wi) = 4 (wo.h) d(h)).
// Each lobe gets theta_h = atan(a tan(w)) with a matched to its width, which spreads a lobe of
// roughness a evenly over w in [0, pi/2): a GGX D cos(theta_h) d(h) becomes sin(w) cos(w) dw dphi /
// pi.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "cbrdf/analytic.h"

namespace cbrdf {
namespace {

constexpr double kPi = std::numbers::pi;

// Five-point Gauss-Legendre rule on [-1, 1].
constexpr std::array<double, 5> kGaussNodes = {-0.9061798459386640, -0.5384693101056831, 0.0,
                                               0.5384693101056831, 0.9061798459386640};
constexpr std::array<double, 5> kGaussWeights = {0.2369268850561891, 0.4786286704993665,
                                                 0.5688888888888889, 0.4786286704993665,
                                                 0.2369268850561891};

// The width of the change of variable for a lobe: its roughness, or for Ashikhmin-Shirley the
// Beckmann-equivalent roughness of its exponent (n = 2 / a^2 - 2).
double lobe_width(const Lobe& lobe) {
  switch (lobe.kind) {
    case LobeKind::kGgx:
    case LobeKind::kWard:
      return lobe.shape;
    case LobeKind::kAshikhminShirley:
      return std::sqrt(2.0 / (lobe.shape + 2.0));
    case LobeKind::kLambertian:
      break;
  }
  return 1.0;
}

void add_lobe_albedo(const Lobe& lobe, const Vec3& wo, int resolution, double out[3]) {
  const AnalyticBrdf single{{lobe}};
  const double a = lobe_width(lobe);
  const int panels = 4 * resolution;
  const int phis = 80 * resolution;
  const double panel_width = (kPi / 2) / panels;
  const double dphi = 2 * kPi / phis;
  for (int p = 0; p < panels; ++p) {
    for (std::size_t q = 0; q < kGaussNodes.size(); ++q) {
      const double w = panel_width * (p + 0.5 + 0.5 * kGaussNodes[q]);
      const double tw = std::tan(w);
      const double theta_h = std::atan(a * tw);
      const double dtheta_dw = a * (1 + tw * tw) / (1 + a * a * tw * tw);
      const double st = std::sin(theta_h), ct = std::cos(theta_h);
      const double weight = 0.5 * panel_width * kGaussWeights[q] * dtheta_dw * st * dphi;
      for (int k = 0; k < phis; ++k) {
        const double phi = (k + 0.5) * dphi;
        const Vec3 h{st * std::cos(phi), st * std::sin(phi), ct};
        const double d = dot(wo, h);
        if (d <= 0) continue;
        const Vec3 wi{2 * d * h.x - wo.x, 2 * d * h.y - wo.y, 2 * d * h.z - wo.z};
        if (wi.z <= 0) continue;
        double f[3];
        single.eval(wi, wo, f);
        const double jacobian = 4 * d * wi.z * weight;
        for (int c = 0; c < 3; ++c) out[c] += f[c] * jacobian;
      }
    }
  }
}

}  // namespace

std::array<double, 3> directional_albedo(const AnalyticBrdf& brdf, const Vec3& wo, int resolution) {
  double sum[3] = {0, 0, 0};
  if (wo.z > 0) {
    for (const Lobe& lobe : brdf.lobes) add_lobe_albedo(lobe, wo, std::max(1, resolution), sum);
  }
  return {sum[0], sum[1], sum[2]};
}

}  // namespace cbrdf
