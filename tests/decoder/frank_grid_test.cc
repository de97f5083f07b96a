// SPDX-License-Identifier: MIT
#include "density/frank_grid.h"

#include <gtest/gtest.h>
#include <quadmath.h>

#include <cmath>
#include <vector>

namespace cbrdf::internal {
namespace {

// The paper's Eq. 13 in __float128 (113-bit mantissa), with 1 + g_{u+v+w} written as
// e^{alpha (u+v+w)} (that sum cancels to 1e-26 at alpha = -20). At |alpha| <= 20 the cancellation
// in g1^2 + g_u g_v g_w loses at most ~30 of the 113 bits, leaving far more than double precision.
double paper_density(double alpha, double u, double v, double w) {
  const __float128 a = alpha;
  auto g = [a](__float128 x) { return expm1q(a * x); };
  const __float128 g1 = g(1), guvw = g(u) * g(v) * g(w);
  return a * a * g1 * g1 * expq(a * (__float128(u) + v + w)) * (g1 * g1 - guvw) /
         ((g1 * g1 + guvw) * (g1 * g1 + guvw) * (g1 * g1 + guvw));
}

const std::vector<double> kU = {1e-12, 0.003, 0.1, 0.25, 0.5, 0.77, 0.95, 0.999, 1 - 1e-9};

TEST(FrankGrid, MatchesPaperClosedFormAtModerateAlpha) {
  for (double alpha : {-20.0, -7.5, -1.0, -1e-3, -1e-7, 1e-7, 0.3, std::log(2.0)}) {
    FrankGrid g;
    g.prepare(alpha, kU, kU, kU);
    for (int i = 0; i < int(kU.size()); ++i)
      for (int j = 0; j < int(kU.size()); ++j)
        for (int k = 0; k < int(kU.size()); ++k) {
          const double ref = paper_density(alpha, kU[i], kU[j], kU[k]);
          const double c = g.density(i, j, k);
          // Small |alpha|: the closed form itself cancels (g ~ alpha), so compare absolutely there.
          const double tol = std::abs(alpha) < 1e-2 ? 1e-6 : 1e-9 * std::abs(double(ref));
          EXPECT_NEAR(c, double(ref), std::max(tol, 1e-300)) << alpha << " " << i << j << k;
        }
  }
}

TEST(FrankGrid, IndependenceAtZero) {
  FrankGrid g;
  g.prepare(0.0, kU, kU, kU);
  double d;
  EXPECT_EQ(g.density(3, 4, 5), 1.0);
  EXPECT_EQ(g.density_and_derivative(3, 4, 5, &d), 1.0);
  // Continuous with the tiny-alpha values on either side.
  FrankGrid n, p;
  n.prepare(-1e-9, kU, kU, kU);
  p.prepare(1e-9, kU, kU, kU);
  double dn, dp;
  n.density_and_derivative(3, 4, 5, &dn);
  p.density_and_derivative(3, 4, 5, &dp);
  EXPECT_NEAR(d, dn, 1e-6);
  EXPECT_NEAR(d, dp, 1e-6);
}

TEST(FrankGrid, DerivativeMatchesFiniteDifference) {
  for (double alpha : {-150.0, -40.0, -5.0, -0.5, -1e-4, 1e-4, 0.5, 0.69}) {
    FrankGrid g, gp, gm;
    const double h = 1e-6 * std::max(1.0, std::abs(alpha));
    g.prepare(alpha, kU, kU, kU);
    gp.prepare(alpha + h, kU, kU, kU);
    gm.prepare(alpha - h, kU, kU, kU);
    for (int i = 1; i < 8; i += 2)
      for (int j = 0; j < 8; j += 3)
        for (int k = 2; k < 9; k += 3) {
          double d;
          const double c = g.density_and_derivative(i, j, k, &d);
          EXPECT_EQ(c, g.density(i, j, k));
          const double fd = (gp.density(i, j, k) - gm.density(i, j, k)) / (2 * h);
          EXPECT_NEAR(d, fd, 1e-5 * std::max(1.0, std::abs(fd))) << alpha << " " << i << j << k;
        }
  }
}

TEST(FrankGrid, StrongDependenceStaysFiniteAndIntegratesToOne) {
  // Midpoint rule on a 200^3 grid of u: the density integrates to 1 (strong dependence piles mass
  // on the diagonal, so a fine grid is needed there: alpha = -30 is resolved at 200 points).
  const int n = 200;
  std::vector<double> u(n);
  for (int i = 0; i < n; ++i) u[i] = (i + 0.5) / n;
  for (double alpha : {-30.0, -3.0, 0.5, std::log(2.0)}) {
    FrankGrid g;
    g.prepare(alpha, u, u, u);
    double sum = 0;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k) {
          const double c = g.density(i, j, k);
          ASSERT_TRUE(std::isfinite(c) && c >= 0) << alpha;
          sum += c;
        }
    EXPECT_NEAR(sum / (double(n) * n * n), 1.0, 2e-3) << alpha;
  }
  FrankGrid g;
  g.prepare(kFrankGridMinAlpha, kU, kU, kU);
  for (int i = 0; i < int(kU.size()); ++i) {
    double d;
    const double c = g.density_and_derivative(i, i, i, &d);
    EXPECT_TRUE(std::isfinite(c) && c >= 0 && std::isfinite(d)) << i;
  }
}

}  // namespace
}  // namespace cbrdf::internal
