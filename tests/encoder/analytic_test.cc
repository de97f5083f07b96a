// SPDX-License-Identifier: MIT
#include "cbrdf/analytic.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <random>
#include <vector>

#include "analytic/microfacet.h"

namespace cbrdf {
namespace {

constexpr double kPi = std::numbers::pi;

Vec3 spherical(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}
Vec3 at_degrees(double theta_deg) {
  return spherical(theta_deg * kPi / 180, 0.0);
}

// Composite 5-point Gauss-Legendre on [a, b]; the tests' own quadrature, apart from the library's.
double integrate(const std::function<double(double)>& f, double a, double b, int panels) {
  static constexpr double kX[5] = {-0.9061798459386640, -0.5384693101056831, 0.0,
                                   0.5384693101056831, 0.9061798459386640};
  static constexpr double kW[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                                   0.4786286704993665, 0.2369268850561891};
  const double h = (b - a) / panels;
  double sum = 0;
  for (int p = 0; p < panels; ++p) {
    for (int q = 0; q < 5; ++q) sum += kW[q] * f(a + h * (p + 0.5 + 0.5 * kX[q]));
  }
  return sum * h / 2;
}

// theta = atan(width tan(w)) spreads a lobe of that width evenly over w in [0, pi/2).
double theta_of_w(double width, double w) {
  return std::atan(width * std::tan(w));
}
double dtheta_dw(double width, double w) {
  const double t = std::tan(w);
  return width * (1 + t * t) / (1 + width * width * t * t);
}

// Every lobe kind over a range of parameters, plus sums: the models the property tests sweep.
std::vector<AnalyticBrdf> all_models() {
  std::vector<AnalyticBrdf> models;
  models.push_back({{lambertian({0.9, 0.5, 0.1})}});
  for (double a : {0.01, 0.08, 0.3, 0.7, 1.5}) models.push_back({{ggx({1.0, 0.6, 0.04}, a)}});
  for (double a : {0.01, 0.1, 0.4, 1.0}) models.push_back({{ward({1.0, 0.5, 0.2}, a)}});
  for (double n : {0.0, 5.0, 100.0, 5000.0}) {
    models.push_back({{ashikhmin_shirley({1.0, 0.3, 0.05}, n)}});
  }
  models.push_back({{lambertian({0.5, 0.2, 0.1}), ggx({0.04, 0.04, 0.04}, 0.2)}});
  models.push_back({{lambertian({0.1, 0.2, 0.4}), ward({0.3, 0.3, 0.3}, 0.15)}});
  return models;
}

TEST(Analytic, ReciprocalForRandomDirections) {
  std::mt19937_64 rng(20100101);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int compared = 0;
  for (const AnalyticBrdf& brdf : all_models()) {
    for (int n = 0; n < 2000; ++n) {
      // Uniform over the hemisphere, grazing directions included.
      const Vec3 wi = spherical(std::acos(u(rng)), 2 * kPi * u(rng));
      const Vec3 wo = spherical(std::acos(u(rng)), 2 * kPi * u(rng));
      double a[3], b[3];
      brdf.eval(wi, wo, a);
      brdf.eval(wo, wi, b);
      for (int c = 0; c < 3; ++c) {
        ASSERT_TRUE(std::isfinite(a[c]));
        ASSERT_GE(a[c], 0.0);
        ASSERT_NEAR(a[c], b[c], 1e-12 * std::max(std::abs(a[c]), 1e-300));
        if (a[c] > 0) ++compared;
      }
    }
  }
  // The sweep must have compared real values, not zeros.
  EXPECT_GT(compared, 50000);
}

TEST(Analytic, ZeroAtAndBelowTheHorizon) {
  const Vec3 up = at_degrees(20);
  const Vec3 horizon{1, 0, 0};
  const Vec3 below{0.6, 0, -0.8};
  for (const AnalyticBrdf& brdf : all_models()) {
    for (const auto& [wi, wo] : {std::pair{horizon, up}, std::pair{up, horizon},
                                 std::pair{below, up}, std::pair{up, below}}) {
      double f[3] = {-1, -1, -1};
      brdf.eval(wi, wo, f);
      EXPECT_EQ(f[0], 0.0);
      EXPECT_EQ(f[1], 0.0);
      EXPECT_EQ(f[2], 0.0);
    }
    // The mirror pair about the normal: every test model's R channel is positive there.
    double f[3];
    brdf.eval(up, Vec3{-up.x, -up.y, up.z}, f);
    EXPECT_GT(f[0], 0.0);
  }
}

TEST(Analytic, LambertianValueAndAlbedoPerChannel) {
  const std::array<double, 3> rho = {0.8, 0.45, 0.15};
  const AnalyticBrdf brdf{{lambertian(rho)}};
  double f[3];
  brdf.eval(at_degrees(10), spherical(1.2, 2.0), f);
  for (int c = 0; c < 3; ++c) EXPECT_DOUBLE_EQ(f[c], rho[c] / kPi);
  for (double deg : {0.0, 30.0, 60.0, 80.0, 89.0}) {
    const std::array<double, 3> a = directional_albedo(brdf, at_degrees(deg));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], rho[c], 1e-3) << "theta_o " << deg;
  }
  EXPECT_EQ(directional_albedo(brdf, Vec3{0.6, 0, -0.8})[0], 0.0);
}

// The normalization every microfacet model relies on: integral of D(h) cos(theta_h) dh = 1.
TEST(Analytic, MicrofacetDistributionsIntegrateToOne) {
  for (double alpha : {0.01, 0.015, 0.08, 0.3, 1.0, 2.0}) {
    for (int beckmann = 0; beckmann < 2; ++beckmann) {
      const double total = 2 * kPi *
                           integrate(
                               [&](double w) {
                                 const double t = theta_of_w(alpha, w);
                                 const double c = std::cos(t), tn = std::tan(t);
                                 const double d = beckmann ? internal::beckmann_d(alpha, c, tn * tn)
                                                           : internal::ggx_d(alpha, c, tn * tn);
                                 return d * c * std::sin(t) * dtheta_dw(alpha, w);
                               },
                               0.0, kPi / 2, 200);
      EXPECT_NEAR(total, 1.0, 1e-3) << (beckmann ? "Beckmann" : "GGX") << " alpha " << alpha;
    }
  }
}

// Smith's G1 is defined by the projected-area identity
// G1(wo) * integral over {h: wo.h > 0} of D(h) (wo.h) dh = cos(theta_o); a wrong Lambda breaks it.
TEST(Analytic, SmithMaskingMatchesProjectedArea) {
  for (double alpha : {0.02, 0.1, 0.5, 1.0, 2.0}) {
    for (double deg : {0.0, 40.0, 70.0, 85.0}) {
      const Vec3 wo = at_degrees(deg);
      const double visible = integrate(
          [&](double w) {
            const double t = theta_of_w(alpha, w);
            const double c = std::cos(t), s = std::sin(t);
            const double d = internal::ggx_d(alpha, c, (s / c) * (s / c));
            return integrate(
                       [&](double phi) {
                         const double wo_h =
                             wo.x * s * std::cos(phi) + wo.y * s * std::sin(phi) + wo.z * c;
                         return std::max(wo_h, 0.0);
                       },
                       0.0, 2 * kPi, 64) *
                   d * s * dtheta_dw(alpha, w);
          },
          0.0, kPi / 2, 100);
      const double tan_o = std::tan(deg * kPi / 180);
      const double g1 = internal::ggx_g1(alpha, tan_o * tan_o);
      EXPECT_NEAR(g1 * visible, wo.z, 2e-4 * std::max(wo.z, 0.1))
          << "alpha " << alpha << " theta_o " << deg;
    }
  }
}

TEST(Analytic, HeightCorrelatedMaskingLiesBetweenSeparableAndMin) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.5);
  for (int n = 0; n < 1000; ++n) {
    const double alpha = 0.01 + u(rng);
    const double ti = std::tan(u(rng)), to = std::tan(u(rng));
    const double g1i = internal::ggx_g1(alpha, ti * ti), g1o = internal::ggx_g1(alpha, to * to);
    const double g2 = internal::ggx_g2(alpha, ti * ti, to * to);
    EXPECT_GE(g2, g1i * g1o * (1 - 1e-14));
    EXPECT_LE(g2, std::min(g1i, g1o) * (1 + 1e-14));
  }
  EXPECT_EQ(internal::ggx_g2(0.5, 0.0, 0.0), 1.0);
  // Height-correlated, not separable: for wi = wo it is 1 / (1 + 2 Lambda), above 1 / (1 +
  // Lambda)^2.
  const double t2 = std::pow(std::tan(1.2), 2);
  const double lambda = internal::ggx_lambda(0.5, t2);
  EXPECT_DOUBLE_EQ(internal::ggx_g2(0.5, t2, t2), 1 / (1 + 2 * lambda));
  EXPECT_GT(internal::ggx_g2(0.5, t2, t2), 1.01 / ((1 + lambda) * (1 + lambda)));
}

// The GGX lobe is assembled from those pieces: D G2 F / (4 cos_i cos_o) with the height-correlated
// G2.
TEST(Analytic, GgxLobeUsesHeightCorrelatedMasking) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double alpha = 0.4;
  const AnalyticBrdf brdf{{ggx({1, 1, 1}, alpha)}};
  for (int n = 0; n < 200; ++n) {
    const double theta_i = 1.4 * u(rng), theta_o = 1.4 * u(rng);
    const Vec3 wi = spherical(theta_i, 2 * kPi * u(rng)), wo = spherical(theta_o, 2 * kPi * u(rng));
    const Vec3 s{wi.x + wo.x, wi.y + wo.y, wi.z + wo.z};
    const double len = std::sqrt(dot(s, s));
    const double cos_h = s.z / len, tan_h = std::tan(std::acos(cos_h));
    const double ti = std::tan(theta_i), to = std::tan(theta_o);
    const double expected = internal::ggx_d(alpha, cos_h, tan_h * tan_h) *
                            internal::ggx_g2(alpha, ti * ti, to * to) /
                            (4 * std::cos(theta_i) * std::cos(theta_o));
    double f[3];
    brdf.eval(wi, wo, f);
    EXPECT_NEAR(f[0], expected, 1e-9 * expected);
  }
}

// Closed forms at wi = wo = n (theta_h = theta_d = 0, no masking, Fresnel = F0).
TEST(Analytic, PeakValuesAtNormalIncidence) {
  const Vec3 n{0, 0, 1};
  const std::array<double, 3> col = {0.9, 0.5, 0.2};
  double f[3];
  for (double alpha : {0.015, 0.3}) {
    AnalyticBrdf{{ggx(col, alpha)}}.eval(n, n, f);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(f[c], col[c] / (4 * kPi * alpha * alpha), 1e-12 * f[c]);
    AnalyticBrdf{{ward(col, alpha)}}.eval(n, n, f);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(f[c], col[c] / (4 * kPi * alpha * alpha), 1e-12 * f[c]);
  }
  AnalyticBrdf{{ashikhmin_shirley(col, 40.0)}}.eval(n, n, f);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(f[c], col[c] * 41.0 / (8 * kPi), 1e-12 * f[c]);
}

// Per channel, a Fresnel-weighted lobe over the same lobe with F0 = 1 is Schlick's
// F0 + (1 - F0)(1 - cos(theta_d))^5, with cos(theta_d) = wi.h.
TEST(Analytic, SchlickFresnelPerChannel) {
  const std::array<double, 3> f0 = {0.04, 0.5, 0.9};
  for (double theta_d_deg : {0.0, 30.0, 60.0, 80.0}) {
    HalfDiff hd;
    hd.theta_h = 0.05;
    hd.theta_d = theta_d_deg * kPi / 180;
    hd.phi_d = 1.0;
    Vec3 wi, wo;
    from_half_diff(hd, &wi, &wo);
    const double m = 1 - std::cos(hd.theta_d);
    for (const auto& [tinted, white] :
         {std::pair{AnalyticBrdf{{ggx(f0, 0.2)}}, AnalyticBrdf{{ggx({1, 1, 1}, 0.2)}}},
          std::pair{AnalyticBrdf{{ashikhmin_shirley(f0, 50)}},
                    AnalyticBrdf{{ashikhmin_shirley({1, 1, 1}, 50)}}}}) {
      double a[3], b[3];
      tinted.eval(wi, wo, a);
      white.eval(wi, wo, b);
      ASSERT_GT(b[0], 0.0);
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(a[c] / b[c], f0[c] + (1 - f0[c]) * std::pow(m, 5), 1e-9)
            << "theta_d " << theta_d_deg << " channel " << c;
      }
    }
  }
  // At grazing theta_d even a dielectric reflects strongly.
  HalfDiff hd;
  hd.theta_d = 85 * kPi / 180;
  hd.theta_h = 0.02;
  Vec3 wi, wo;
  from_half_diff(hd, &wi, &wo);
  double a[3], b[3];
  AnalyticBrdf{{ggx(f0, 0.2)}}.eval(wi, wo, a);
  AnalyticBrdf{{ggx({1, 1, 1}, 0.2)}}.eval(wi, wo, b);
  EXPECT_GT(a[0] / b[0], 0.5);
}

// An analytic result that pins the whole GGX lobe (D, G and the 1/(4 cos cos) factor): for
// alpha = 1, F0 = 1 and wo = n, D cos(theta_h) is uniform in u = sin^2(theta_h), wi has
// cos(theta_i) = 1 - 2u, G = (1 - 2u) / (1 - u), and the albedo is the integral of G over
// u in [0, 1/2] = 1 - ln 2.
TEST(Analytic, GgxAlbedoClosedForm) {
  const AnalyticBrdf brdf{{ggx({1, 1, 1}, 1.0)}};
  const std::array<double, 3> a = directional_albedo(brdf, Vec3{0, 0, 1}, 16);
  EXPECT_NEAR(a[0], 1 - std::log(2.0), 1e-4);
}

// White lobes (colour 1) never reflect more than they receive, at any wo, including grazing
// (where a GGX lobe without its masking term would exceed 1), and narrow lobes lose almost nothing
// at normal incidence (where a double-counted or squared masking term would show).
TEST(Analytic, EnergyConservingAtEveryAngle) {
  // The quadrature's error, measured against a doubled resolution, is below 1e-3 even at 89.9 deg.
  constexpr double kQuadratureTolerance = 1e-3;
  std::vector<AnalyticBrdf> white;
  for (double a : {0.01, 0.08, 0.5, 1.0, 2.0}) white.push_back({{ggx({1, 1, 1}, a)}});
  for (double a : {0.01, 0.2, 0.5, 1.0}) white.push_back({{ward({1, 1, 1}, a)}});
  for (double n : {0.0, 10.0, 300.0, 1e4}) white.push_back({{ashikhmin_shirley({1, 1, 1}, n)}});
  white.push_back({{lambertian({1, 1, 1})}});
  for (const AnalyticBrdf& brdf : white) {
    for (double deg : {0.0, 20.0, 45.0, 60.0, 75.0, 85.0, 89.0, 89.9}) {
      const double a = directional_albedo(brdf, at_degrees(deg), 6)[0];
      EXPECT_LE(a, 1.0 + kQuadratureTolerance)
          << lobe_kind_name(brdf.lobes[0].kind) << " " << brdf.lobes[0].shape << " at " << deg;
      EXPECT_GT(a, 0.0);
    }
  }
  for (const AnalyticBrdf& brdf :
       {AnalyticBrdf{{ggx({1, 1, 1}, 0.01)}}, AnalyticBrdf{{ward({1, 1, 1}, 0.01)}}}) {
    EXPECT_GT(directional_albedo(brdf, Vec3{0, 0, 1})[0], 0.999);
  }
}

TEST(Analytic, ParameterVectorRoundTrip) {
  AnalyticBrdf brdf{{lambertian({0.1, 0.2, 0.3}), ggx({0.04, 0.05, 0.06}, 0.2),
                     ward({0.3, 0.2, 0.1}, 0.4), ashikhmin_shirley({0.5, 0.6, 0.7}, 80)}};
  ASSERT_EQ(brdf.num_params(), 3 + 4 + 4 + 4);
  std::vector<double> p(brdf.num_params());
  brdf.to_params(p);
  EXPECT_EQ(p, (std::vector<double>{0.1, 0.2, 0.3, 0.04, 0.05, 0.06, 0.2, 0.3, 0.2, 0.1, 0.4, 0.5,
                                    0.6, 0.7, 80}));
  for (double& v : p) v *= 1.5;
  ASSERT_TRUE(brdf.from_params(p).ok());
  std::vector<double> q(brdf.num_params());
  brdf.to_params(q);
  EXPECT_EQ(p, q);
  EXPECT_EQ(brdf.lobes[2].kind, LobeKind::kWard);
  EXPECT_DOUBLE_EQ(brdf.lobes[1].shape, 0.3);
}

TEST(Analytic, RejectsParametersOutsideTheirDomain) {
  AnalyticBrdf brdf{{lambertian({0.1, 0.2, 0.3}), ggx({0.04, 0.04, 0.04}, 0.2)}};
  const AnalyticBrdf before = brdf;
  const auto same = [&] {
    std::vector<double> a(brdf.num_params()), b(before.num_params());
    brdf.to_params(a);
    before.to_params(b);
    return a == b;
  };

  Status s = brdf.from_params(std::vector<double>{1, 2, 3});
  EXPECT_EQ(s.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(s.message().find("got 3 values"), std::string::npos) << s.message();
  EXPECT_TRUE(same());

  s = brdf.from_params(std::vector<double>{0.1, 0.2, 0.3, 0.04, -0.04, 0.04, 0.2});
  EXPECT_EQ(s.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(s.message().find("lobe 1 (ggx)"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("colour G"), std::string::npos) << s.message();
  EXPECT_TRUE(same());

  s = brdf.from_params(std::vector<double>{0.1, 0.2, 0.3, 0.04, 0.04, 0.04, 0.0});
  EXPECT_EQ(s.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(s.message().find("roughness"), std::string::npos) << s.message();
  EXPECT_TRUE(same());

  s = brdf.from_params(std::vector<double>{0.1, NAN, 0.3, 0.04, 0.04, 0.04, 0.2});
  EXPECT_EQ(s.code(), ErrorCode::kInvalidArgument);
  EXPECT_TRUE(same());

  EXPECT_EQ(AnalyticBrdf{{ashikhmin_shirley({1, 1, 1}, -1)}}.validate().code(),
            ErrorCode::kInvalidArgument);
  const AnalyticBrdf unknown_kind{{Lobe{LobeKind(9), {0, 0, 0}, 0}}};
  EXPECT_EQ(unknown_kind.validate().code(), ErrorCode::kInvalidArgument);
  EXPECT_TRUE(AnalyticBrdf{{ward({1, 1, 1}, kMinAlpha)}}.validate().ok());
}

}  // namespace
}  // namespace cbrdf
