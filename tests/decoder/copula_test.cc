// SPDX-License-Identifier: MIT
// Behaviour of the copula families: domains, no NaN anywhere, density vs CDF, symmetry,
// normalisation, the fast path, conditional distributions and their inverses, Frank's edge cases.
// Precision against higher-precision references is in copula_precision_test.cc.
#include "copula/copula.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace cbrdf {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kLn2 = 0.69314718055994530942;

const std::vector<double> kEdgeU = {0.0, 1e-300, 1e-12, 1e-6,     0.1,       0.3,
                                    0.5, 0.7,    0.9,   1 - 1e-6, 1 - 1e-12, 1.0};

struct Case {
  CopulaFamily family;
  std::vector<double> hard;      // the whole domain's awkward values
  std::vector<double> moderate;  // where quadrature and finite differences are meaningful
};

const std::vector<Case>& cases() {
  static const std::vector<Case> c = {
      {CopulaFamily::kIndependence, {0.0}, {0.0}},
      {CopulaFamily::kFrank,
       {0.0, 1e-300, -1e-300, 1e-12, -1e-12, 1e-6, -1e-6, 0.5, kLn2, -1, -50, -300, -745, -1e4},
       {-5.0, -1.0, 0.5, kLn2}},
      {CopulaFamily::kClayton,
       {0.0, 1e-300, 1e-12, 1e-6, 0.5, 1.0, 2.0, 50, 300, 745, 1e4},
       {0.3, 1.0, 2.0}},
      {CopulaFamily::kGumbel, {1.0, 1 + 1e-12, 1 + 1e-6, 1.5, 2, 50, 300, 745, 1e4}, {1.3, 2.0}},
      {CopulaFamily::kJoe, {1.0, 1 + 1e-12, 1 + 1e-6, 1.5, 2, 50, 300, 745, 1e4}, {1.3, 2.0}},
  };
  return c;
}

std::string where(CopulaFamily f, double theta) {
  return std::string(family_name(f)) + " theta=" + std::to_string(theta);
}

TEST(CopulaFamilyNames, RoundTripAndValidity) {
  for (int raw = 0; raw < 256; ++raw) {
    const bool valid = family_valid(std::uint8_t(raw));
    EXPECT_EQ(valid, raw <= 4) << raw;
    if (!valid) continue;
    const auto f = CopulaFamily(raw);
    EXPECT_EQ(family_from_name(family_name(f)), f);
    EXPECT_EQ(copula_for(f).family(), f);
  }
  EXPECT_EQ(family_name(CopulaFamily::kFrank), "frank");
  EXPECT_EQ(family_name(CopulaFamily::kIndependence), "independence");
  EXPECT_FALSE(family_from_name("Frank").has_value());
  EXPECT_FALSE(family_from_name("").has_value());
}

TEST(CopulaDomain, BoundsAndIndependencePoint) {
  const Copula& frank = copula_for(CopulaFamily::kFrank);
  EXPECT_TRUE(frank.in_domain(kLn2));
  EXPECT_TRUE(frank.in_domain(-1e300));
  EXPECT_FALSE(frank.in_domain(0.6932));
  EXPECT_FALSE(frank.in_domain(-kInf));
  EXPECT_FALSE(frank.in_domain(std::nan("")));
  EXPECT_TRUE(copula_for(CopulaFamily::kClayton).in_domain(0.0));
  EXPECT_FALSE(copula_for(CopulaFamily::kClayton).in_domain(-1e-9));
  EXPECT_FALSE(copula_for(CopulaFamily::kClayton).in_domain(kInf));
  for (auto f : {CopulaFamily::kGumbel, CopulaFamily::kJoe}) {
    EXPECT_TRUE(copula_for(f).in_domain(1.0));
    EXPECT_FALSE(copula_for(f).in_domain(std::nextafter(1.0, 0.0)));
  }
  EXPECT_TRUE(copula_for(CopulaFamily::kIndependence).in_domain(0.0));
  EXPECT_FALSE(copula_for(CopulaFamily::kIndependence).in_domain(1.0));
  // The independence point of each family gives c = 1 everywhere.
  for (const Case& c : cases()) {
    const Copula& cop = copula_for(c.family);
    const double ind = cop.domain().independence;
    EXPECT_TRUE(cop.in_domain(ind));
    for (double a : kEdgeU)
      for (double b : kEdgeU) EXPECT_EQ(cop.density(a, b, 0.37, ind), 1.0) << where(c.family, ind);
  }
}

TEST(CopulaDomain, OutsideGivesNaNAndAnActionableStatus) {
  const Copula& frank = copula_for(CopulaFamily::kFrank);
  EXPECT_TRUE(std::isnan(frank.log_density(0.5, 0.5, 0.5, 0.7)));
  EXPECT_TRUE(std::isnan(frank.cdf(0.5, 0.5, 0.5, 0.7)));
  EXPECT_TRUE(std::isnan(frank.conditional2(0.5, 0.5, 0.7)));
  EXPECT_TRUE(std::isnan(frank.log_density(1.5, 0.5, 0.5, -1)));
  EXPECT_TRUE(std::isnan(frank.log_density(-0.1, 0.5, 0.5, -1)));
  EXPECT_TRUE(std::isnan(frank.log_density(std::nan(""), 0.5, 0.5, -1)));
  const Status ok = frank.check_parameter(-3);
  EXPECT_TRUE(ok.ok());
  const Status bad = frank.check_parameter(0.7);
  EXPECT_EQ(bad.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(bad.message().find("frank"), std::string::npos) << bad.message();
  EXPECT_NE(bad.message().find("0.7"), std::string::npos) << bad.message();
  EXPECT_NE(bad.message().find("0.693"), std::string::npos) << bad.message();
  EXPECT_EQ(copula_for(CopulaFamily::kGumbel).check_parameter(0.5).code(),
            ErrorCode::kInvalidArgument);
}

// No function returns NaN for u in [0,1] and theta in the domain; results lie in their ranges.
TEST(CopulaNumerics, NeverNaNOnTheEdgeGrid) {
  for (const Case& c : cases()) {
    const Copula& cop = copula_for(c.family);
    for (double theta : c.hard) {
      for (double a : kEdgeU) {
        const Copula::AxisTerm t = cop.axis_term(a, theta);
        ASSERT_FALSE(std::isnan(t.psi) || std::isnan(t.log_abs_dpsi)) << where(c.family, theta);
        ASSERT_GE(t.psi, 0.0);
        const double g = cop.log_generator(a, theta);
        ASSERT_FALSE(std::isnan(g)) << where(c.family, theta) << " u=" << a;
        for (double b : kEdgeU) {
          const double c2 = cop.conditional2(b, a, theta);
          ASSERT_TRUE(c2 >= 0 && c2 <= 1) << where(c.family, theta) << " " << a << " " << b;
          const double d2 = cop.density2(a, b, theta);
          ASSERT_TRUE(d2 >= 0) << where(c.family, theta) << " " << a << " " << b;
          const double p = cop.conditional2_inverse(std::min(1.0, b), a, theta);
          ASSERT_TRUE(p >= 0 && p <= 1) << where(c.family, theta) << " " << a << " " << b;
          for (double d : kEdgeU) {
            const double l = cop.log_density(a, b, d, theta);
            ASSERT_FALSE(std::isnan(l))
                << where(c.family, theta) << " u=" << a << "," << b << "," << d;
            const double cdf = cop.cdf(a, b, d, theta);
            ASSERT_TRUE(cdf >= 0 && cdf <= std::min({a, b, d}) * (1 + 1e-12))
                << where(c.family, theta) << " u=" << a << "," << b << "," << d << " " << cdf;
            const double c3 = cop.conditional3(d, a, b, theta);
            ASSERT_TRUE(c3 >= 0 && c3 <= 1) << where(c.family, theta) << " " << a << b << d;
          }
        }
        // Uniform margins: C(u, 1, 1) = u.
        EXPECT_NEAR(cop.cdf(a, 1.0, 1.0, theta), a, 1e-12 * std::max(a, 1e-300))
            << where(c.family, theta);
      }
    }
  }
}

TEST(CopulaNumerics, SymmetricInItsArguments) {
  for (const Case& c : cases()) {
    const Copula& cop = copula_for(c.family);
    for (double theta : c.hard)
      for (double a : kEdgeU)
        for (double b : kEdgeU)
          for (double d : {1e-12, 0.3, 0.9}) {
            const double base = cop.log_density(a, b, d, theta);
            for (double other : {cop.log_density(b, a, d, theta), cop.log_density(d, b, a, theta),
                                 cop.log_density(a, d, b, theta)}) {
              if (std::isinf(base)) {
                EXPECT_EQ(other, base);
              } else {
                EXPECT_NEAR(other, base, 1e-12 * std::max(1.0, std::abs(base)))
                    << where(c.family, theta);
              }
            }
          }
  }
}

// Composite Gauss-Legendre nodes on [0,1], graded geometrically toward both ends where the
// densities have their singular corners.
struct Rule {
  std::vector<double> x, w;
};

Rule gauss_legendre(int n) {
  Rule r;
  for (int i = 1; i <= n; ++i) {
    double x = std::cos(M_PI * (i - 0.25) / (n + 0.5)), dp = 0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1, p1 = x;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (x * p1 - p0) / (x * x - 1);
      const double dx = p1 / dp;
      x -= dx;
      if (std::abs(dx) < 1e-16) break;
    }
    r.x.push_back(x);
    r.w.push_back(2 / ((1 - x * x) * dp * dp));
  }
  return r;
}

Rule composite(const std::vector<double>& breaks, int n) {
  const Rule g = gauss_legendre(n);
  Rule r;
  for (std::size_t k = 0; k + 1 < breaks.size(); ++k) {
    const double a = breaks[k], b = breaks[k + 1];
    for (int i = 0; i < n; ++i) {
      r.x.push_back(0.5 * (a + b) + 0.5 * (b - a) * g.x[std::size_t(i)]);
      r.w.push_back(0.5 * (b - a) * g.w[std::size_t(i)]);
    }
  }
  return r;
}

TEST(CopulaNumerics, DensityIntegratesToOne) {
  // Geometric grading (ratio sqrt(10)) toward 0 and 1, where the densities concentrate.
  std::vector<double> breaks = {0.0};
  for (double e = -7; e <= -1.5; e += 0.5) breaks.push_back(std::pow(10.0, e));
  for (double x : {0.1, 0.3, 0.5, 0.7, 0.9}) breaks.push_back(x);
  for (double e = -1.5; e >= -7; e -= 0.5) breaks.push_back(1 - std::pow(10.0, e));
  breaks.push_back(1.0);
  const Rule r = composite(breaks, 5);
  const std::size_t n = r.x.size();
  for (const Case& c : cases()) {
    const Copula& cop = copula_for(c.family);
    for (double theta : c.moderate) {
      // The density is symmetric: sum over i <= j <= k with the number of distinct permutations.
      double total = 0;
      for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = i; j < n; ++j)
          for (std::size_t k = j; k < n; ++k) {
            const double perms = (i == j && j == k) ? 1 : (i == j || j == k) ? 3 : 6;
            total += perms * r.w[i] * r.w[j] * r.w[k] * cop.density(r.x[i], r.x[j], r.x[k], theta);
          }
      EXPECT_NEAR(total, 1.0, 2e-7) << where(c.family, theta);
    }
  }
}

// The integral of c over a box equals the CDF's volume of that box (inclusion-exclusion).
TEST(CopulaNumerics, DensityIntegratesToTheCdfOverBoxes) {
  const double lo[3] = {0.2, 0.05, 0.6}, hi[3] = {0.55, 0.7, 0.97};
  std::vector<Rule> rules;
  for (int d = 0; d < 3; ++d) {
    std::vector<double> breaks;
    for (int k = 0; k <= 6; ++k) breaks.push_back(lo[d] + (hi[d] - lo[d]) * k / 6);
    rules.push_back(composite(breaks, 8));
  }
  for (const Case& c : cases()) {
    const Copula& cop = copula_for(c.family);
    for (double theta : c.moderate) {
      double integral = 0;
      for (std::size_t i = 0; i < rules[0].x.size(); ++i)
        for (std::size_t j = 0; j < rules[1].x.size(); ++j)
          for (std::size_t k = 0; k < rules[2].x.size(); ++k)
            integral += rules[0].w[i] * rules[1].w[j] * rules[2].w[k] *
                        cop.density(rules[0].x[i], rules[1].x[j], rules[2].x[k], theta);
      double volume = 0;
      for (int corner = 0; corner < 8; ++corner) {
        double u[3];
        int ones = 0;
        for (int d = 0; d < 3; ++d) {
          const bool up = (corner >> d) & 1;
          u[d] = up ? hi[d] : lo[d];
          ones += up;
        }
        volume += ((3 - ones) % 2 ? -1 : 1) * cop.cdf(u[0], u[1], u[2], theta);
      }
      EXPECT_NEAR(integral / volume, 1.0, 1e-10) << where(c.family, theta);
    }
  }
}

TEST(CopulaNumerics, DensityIsTheMixedThirdPartialOfTheCdf) {
  const double h = 1e-3;
  for (const Case& c : cases()) {
    const Copula& cop = copula_for(c.family);
    for (double theta : c.moderate)
      for (double a : {0.2, 0.5, 0.8})
        for (double b : {0.3, 0.6})
          for (double d : {0.25, 0.9}) {
            double fd = 0;
            for (int corner = 0; corner < 8; ++corner) {
              const int s1 = corner & 1 ? 1 : -1, s2 = corner & 2 ? 1 : -1,
                        s3 = corner & 4 ? 1 : -1;
              fd += s1 * s2 * s3 * cop.cdf(a + s1 * h, b + s2 * h, d + s3 * h, theta);
            }
            fd /= 8 * h * h * h;
            EXPECT_NEAR(fd / cop.density(a, b, d, theta), 1.0, 1e-4) << where(c.family, theta);
          }
  }
}

TEST(CopulaNumerics, FastPathAgreesWithLogDensity) {
  for (const Case& c : cases()) {
    const Copula& cop = copula_for(c.family);
    std::size_t compared = 0;
    for (double theta : c.hard) {
      const Copula::FastPath prepared = cop.prepare_fast_path(theta);
      // The documented domain of the fast path: u in (0,1) with phi(u) a finite normal double.
      std::vector<Copula::AxisTerm> terms;
      std::vector<double> us;
      for (double u : kEdgeU) {
        const Copula::AxisTerm t = cop.axis_term(u, theta);
        if (u > 0 && u < 1 && std::isfinite(t.psi) && std::isnormal(t.psi)) {
          terms.push_back(t);
          us.push_back(u);
        }
      }
      compared += us.size() * us.size() * us.size();
      for (std::size_t i = 0; i < us.size(); ++i)
        for (std::size_t j = 0; j < us.size(); ++j)
          for (std::size_t k = 0; k < us.size(); ++k) {
            const double s = terms[i].psi + terms[j].psi + terms[k].psi;
            const double fast = cop.log_abs_inverse_third_derivative(s, theta) +
                                terms[i].log_abs_dpsi + terms[j].log_abs_dpsi +
                                terms[k].log_abs_dpsi;
            const double fast_prepared = cop.log_abs_inverse_third_derivative(s, prepared) +
                                         terms[i].log_abs_dpsi + terms[j].log_abs_dpsi +
                                         terms[k].log_abs_dpsi;
            const double want = cop.log_density(us[i], us[j], us[k], theta);
            if (std::isinf(want)) {
              EXPECT_EQ(fast, want) << where(c.family, theta);
              EXPECT_EQ(fast_prepared, want) << where(c.family, theta);
            } else {
              EXPECT_NEAR(fast, want, 1e-10 * std::max(1.0, std::abs(want)))
                  << where(c.family, theta) << " u=" << us[i] << "," << us[j] << "," << us[k];
              EXPECT_NEAR(fast_prepared, want, 1e-10 * std::max(1.0, std::abs(want)))
                  << where(c.family, theta) << " u=" << us[i] << "," << us[j] << "," << us[k];
            }
          }
    }
    // (Gumbel at theta = 1e4 has no u where phi is a normal double: there only log_density works.)
    EXPECT_GE(compared, 1000u) << family_name(c.family);
  }
}

TEST(CopulaConditionals, MatchDerivativesOfTheMargins) {
  const double h = 1e-5;
  for (const Case& c : cases()) {
    const Copula& cop = copula_for(c.family);
    for (double theta : c.moderate)
      for (double a : {0.1, 0.4, 0.75})
        for (double b : {0.2, 0.5, 0.93}) {
          // C(u2 | u1) = d/du1 C(u1, u2, 1)
          const double fd2 = (cop.cdf2(a + h, b, theta) - cop.cdf2(a - h, b, theta)) / (2 * h);
          EXPECT_NEAR(cop.conditional2(b, a, theta), fd2, 1e-8) << where(c.family, theta);
          // c(u1, u2) = d/du2 C(u2 | u1)
          const double fdc =
              (cop.conditional2(b + h, a, theta) - cop.conditional2(b - h, a, theta)) / (2 * h);
          EXPECT_NEAR(cop.density2(a, b, theta) / fdc, 1.0, 1e-6) << where(c.family, theta);
          for (double d : {0.3, 0.8}) {
            // C(u3 | u1, u2) = d2/du1 du2 C(u1, u2, u3) / c(u1, u2)
            double fd = 0;
            for (int s1 : {-1, 1})
              for (int s2 : {-1, 1})
                fd += s1 * s2 * cop.cdf(a + s1 * 1e-4, b + s2 * 1e-4, d, theta);
            fd /= 4e-8 * cop.density2(a, b, theta);
            EXPECT_NEAR(cop.conditional3(d, a, b, theta), fd, 1e-6) << where(c.family, theta);
          }
        }
  }
}

TEST(CopulaConditionals, MonotoneAndInvertible) {
  std::vector<double> grid;
  for (int i = 0; i <= 200; ++i) grid.push_back(i / 200.0);
  for (const Case& c : cases()) {
    const Copula& cop = copula_for(c.family);
    for (double theta : c.hard)
      for (double a : {1e-12, 0.1, 0.5, 0.9, 1 - 1e-9})
        for (double b : {1e-6, 0.4, 0.97}) {
          double prev2 = 0, prev3 = 0;
          for (double v : grid) {
            const double c2 = cop.conditional2(v, a, theta);
            const double c3 = cop.conditional3(v, a, b, theta);
            EXPECT_GE(c2, prev2) << where(c.family, theta);
            EXPECT_GE(c3, prev3) << where(c.family, theta);
            prev2 = c2;
            prev3 = c3;
          }
          EXPECT_EQ(prev2, 1.0);
          // The inverse is the solution to within a few ulp of v: C(v - 4ulp) <= p <= C(v + 4ulp)
          // (where C is steep, as near 1 at large theta, no double v hits p more closely).
          auto ulps = [](double v, int k) {
            for (int i = 0; i < std::abs(k); ++i) v = std::nextafter(v, k > 0 ? 2.0 : -1.0);
            return std::clamp(v, 0.0, 1.0);
          };
          for (double p : {1e-9, 0.01, 0.3, 0.5, 0.77, 0.999}) {
            const double tol = 1e-12 * p;
            const double v2 = cop.conditional2_inverse(p, a, theta);
            EXPECT_LE(cop.conditional2(ulps(v2, -4), a, theta), p + tol)
                << where(c.family, theta) << " u1=" << a << " p=" << p << " v=" << v2;
            EXPECT_GE(cop.conditional2(ulps(v2, 4), a, theta), p - tol)
                << where(c.family, theta) << " u1=" << a << " p=" << p << " v=" << v2;
            const double v3 = cop.conditional3_inverse(p, a, b, theta);
            EXPECT_LE(cop.conditional3(ulps(v3, -4), a, b, theta), p + tol)
                << where(c.family, theta) << " u1=" << a << " u2=" << b << " p=" << p;
            EXPECT_GE(cop.conditional3(ulps(v3, 4), a, b, theta), p - tol)
                << where(c.family, theta) << " u1=" << a << " u2=" << b << " p=" << p;
          }
        }
  }
}

TEST(CopulaConditionals, InverseRecoversTheArgumentAtModerateTheta) {
  for (const Case& c : cases()) {
    const Copula& cop = copula_for(c.family);
    for (double theta : c.moderate)
      for (double a : {0.05, 0.5, 0.95})
        for (double v : {0.01, 0.3, 0.6, 0.99}) {
          EXPECT_NEAR(cop.conditional2_inverse(cop.conditional2(v, a, theta), a, theta), v, 1e-12)
              << where(c.family, theta);
          EXPECT_NEAR(cop.conditional3_inverse(cop.conditional3(v, a, 0.4, theta), a, 0.4, theta),
                      v, 1e-12)
              << where(c.family, theta);
        }
  }
}

TEST(CopulaConditionals, ValueAtU1ZeroIsTheLimit) {
  // C(u2 | u1) approaches its value at u1 = 0 monotonically as u1 -> 0 (slowly for Gumbel, whose
  // tail ratio converges like exp(-x s^{1/theta - 1})).
  for (const Case& c : cases()) {
    const Copula& cop = copula_for(c.family);
    for (double theta : c.moderate)
      for (double b : {0.1, 0.5, 0.9}) {
        const double at0 = cop.conditional2(b, 0.0, theta);
        double prev = kInf;
        for (double a : {1e-3, 1e-10, 1e-100, 1e-300}) {
          const double gap = std::abs(cop.conditional2(b, a, theta) - at0);
          EXPECT_LE(gap, prev + 1e-12) << where(c.family, theta) << " u1=" << a;
          prev = gap;
        }
        if (c.family != CopulaFamily::kGumbel) {
          EXPECT_LT(prev, 1e-12) << where(c.family, theta);
        }
      }
  }
  // The limits themselves: e^{-phi(u2)} for Frank and Joe, 1 for Clayton and Gumbel.
  const Copula& frank = copula_for(CopulaFamily::kFrank);
  EXPECT_NEAR(frank.conditional2(0.5, 0.0, -2.0), std::exp(-frank.generator(0.5, -2.0)), 1e-15);
  EXPECT_EQ(copula_for(CopulaFamily::kGumbel).conditional2(0.5, 0.0, 2.0), 1.0);
  EXPECT_EQ(copula_for(CopulaFamily::kClayton).conditional2(0.5, 0.0, 2.0), 1.0);
}

TEST(CopulaGenerator, InverseAndDerivative) {
  for (const Case& c : cases()) {
    const Copula& cop = copula_for(c.family);
    for (double theta : c.hard)
      for (double u : {1e-6, 0.1, 0.5, 0.9, 1 - 1e-6}) {
        const double s = cop.generator(u, theta);
        if (!(s > 0 && std::isfinite(s) && std::isnormal(s))) continue;  // documented range
        EXPECT_NEAR(cop.generator_inverse(s, theta), u, 1e-13 * std::max(u, 1e-3))
            << where(c.family, theta);
      }
    for (double theta : c.moderate)
      for (double u : {0.1, 0.5, 0.9}) {
        const double h = 1e-6;
        const double fd = (cop.generator(u + h, theta) - cop.generator(u - h, theta)) / (2 * h);
        EXPECT_NEAR(std::log(std::abs(fd)), cop.log_abs_generator_derivative(u, theta), 1e-8)
            << where(c.family, theta);
      }
  }
}

TEST(CopulaDerivative, DLogDensityDThetaMatchesADifferenceQuotient) {
  for (const Case& c : cases()) {
    if (c.family == CopulaFamily::kIndependence) continue;  // a single parameter value
    const Copula& cop = copula_for(c.family);
    for (double theta : c.moderate)
      for (double a : {0.1, 0.5, 0.9})
        for (double b : {0.3, 0.7}) {
          const double d = 0.6;
          const double got = cop.d_log_density_dtheta(a, b, d, theta);
          const double e = 1e-5;
          // A plain difference on the inside of the domain (one-sided at Frank's ln 2).
          const double want =
              cop.in_domain(theta + e)
                  ? (cop.log_density(a, b, d, theta + e) - cop.log_density(a, b, d, theta - e)) /
                        (2 * e)
                  : (cop.log_density(a, b, d, theta) - cop.log_density(a, b, d, theta - e)) / e;
          EXPECT_NEAR(got, want, 1e-4 * std::max(1.0, std::abs(want))) << where(c.family, theta);
        }
  }
  // At the independence point of Gumbel and Joe the derivative is one-sided and finite.
  for (auto f : {CopulaFamily::kGumbel, CopulaFamily::kJoe}) {
    const double g = copula_for(f).d_log_density_dtheta(0.2, 0.6, 0.9, 1.0);
    const double q = (copula_for(f).log_density(0.2, 0.6, 0.9, 1.0 + 1e-6)) / 1e-6;
    EXPECT_NEAR(g, q, 1e-4 * std::max(1.0, std::abs(q))) << family_name(f);
  }
}

// ---- Frank specifics ----

TEST(CopulaFrank, IndependenceAtZeroAndTinyTheta) {
  const Copula& f = copula_for(CopulaFamily::kFrank);
  for (double a : kEdgeU)
    for (double b : kEdgeU)
      for (double d : kEdgeU) {
        EXPECT_EQ(f.density(a, b, d, 0.0), 1.0);
        EXPECT_NEAR(f.density(a, b, d, 1e-300), 1.0, 1e-15);
        EXPECT_NEAR(f.density(a, b, d, -1e-300), 1.0, 1e-15);
        // density = 1 + O(theta): no jump between tiny and small parameters.
        EXPECT_NEAR(f.density(a, b, d, -1e-8), 1.0, 1e-7);
        EXPECT_NEAR(f.density(a, b, d, 1e-8), 1.0, 1e-7);
      }
  for (double theta : {-1e-3, -1e-6, -1e-9, 1e-9, 1e-6, 1e-3}) {
    const double slope = (f.density(0.9, 0.9, 0.9, theta) - 1.0) / theta;
    EXPECT_NEAR(slope, (f.density(0.9, 0.9, 0.9, -1e-3) - 1.0) / -1e-3, 0.02) << theta;
  }
}

TEST(CopulaFrank, BoundaryValuesAreTheLimits) {
  const Copula& f = copula_for(CopulaFamily::kFrank);
  for (double theta : {-50.0, -1.0, 0.5})
    for (double b : {0.2, 0.9})
      for (double d : {0.4, 1.0}) {
        EXPECT_NEAR(f.log_density(0.0, b, d, theta), f.log_density(1e-300, b, d, theta), 1e-12);
        EXPECT_NEAR(f.log_density(1.0, b, d, theta), f.log_density(1 - 1e-16, b, d, theta), 1e-12);
      }
}

TEST(CopulaFrank, DomainEndsExactlyAtLn2) {
  const Copula& f = copula_for(CopulaFamily::kFrank);
  // At ln 2 the density is >= 0 everywhere and reaches ~0 at the corner (1,1,1).
  double least = kInf;
  for (double a : kEdgeU)
    for (double b : kEdgeU)
      for (double d : kEdgeU) {
        const double c = f.density(a, b, d, kLn2);
        ASSERT_GE(c, 0.0);
        least = std::min(least, c);
      }
  EXPECT_LT(least, 1e-12);
  // Just above ln 2 the function is no longer a density: the paper's Eq. 13 (exact algebra,
  // evaluated in long double) is negative near the corner, and the library refuses the parameter.
  const long double alpha = 0.70L;
  auto g = [&](long double x) { return expm1l(alpha * x); };
  const long double g1s = g(1) * g(1), guvy = g(0.999L) * g(0.999L) * g(0.999L);
  const long double eq13 = alpha * alpha * g1s * (1 + g(3 * 0.999L)) * (g1s - guvy) /
                           ((g1s + guvy) * (g1s + guvy) * (g1s + guvy));
  EXPECT_LT(eq13, 0.0L);
  EXPECT_FALSE(f.in_domain(0.70));
  EXPECT_TRUE(std::isnan(f.density(0.999, 0.999, 0.999, 0.70)));
  // And Eq. 13 agrees with the library just inside the domain at the same point.
  const long double a2 = kLn2;
  auto g2 = [&](long double x) { return expm1l(a2 * x); };
  const long double h1s = g2(1) * g2(1), huvy = g2(0.5L) * g2(0.5L) * g2(0.5L);
  const long double in13 =
      a2 * a2 * h1s * (1 + g2(1.5L)) * (h1s - huvy) / ((h1s + huvy) * (h1s + huvy) * (h1s + huvy));
  EXPECT_NEAR(f.density(0.5, 0.5, 0.5, kLn2), double(in13), 1e-14);
}

TEST(CopulaBoundary, FaceValuesFollowTheInterior) {
  // Clayton (theta > 0) vanishes on faces u_i = 0; Gumbel and Joe vanish on faces u_i = 1 and are
  // infinite at the corner (1,1,1); the interior approaches those values.
  const Copula& cl = copula_for(CopulaFamily::kClayton);
  EXPECT_EQ(cl.log_density(0.0, 0.3, 0.6, 2.0), -kInf);
  EXPECT_LT(cl.density(1e-100, 0.3, 0.6, 2.0), cl.density(1e-3, 0.3, 0.6, 2.0));
  EXPECT_EQ(cl.log_density(0.0, 0.0, 0.0, 2.0), kInf);
  EXPECT_GT(cl.density(1e-100, 1e-100, 1e-100, 2.0), 1e100);
  for (auto fam : {CopulaFamily::kGumbel, CopulaFamily::kJoe}) {
    const Copula& c = copula_for(fam);
    EXPECT_EQ(c.log_density(1.0, 0.3, 0.6, 2.0), -kInf);
    EXPECT_LT(c.density(1 - 1e-15, 0.3, 0.6, 2.0), c.density(1 - 1e-3, 0.3, 0.6, 2.0));
    EXPECT_EQ(c.log_density(1.0, 1.0, 1.0, 2.0), kInf);
    EXPECT_GT(c.density(1 - 1e-15, 1 - 1e-15, 1 - 1e-15, 2.0), 1e10);
  }
}

}  // namespace
}  // namespace cbrdf
