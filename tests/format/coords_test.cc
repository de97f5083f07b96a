// SPDX-License-Identifier: MIT
#include "cbrdf/coords.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

namespace cbrdf {
namespace {

constexpr double kPi = std::numbers::pi;

Vec3 spherical(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

// The reference MERL reader (BRDFRead.cpp), transcribed: spherical angles in, bin index out.
void reference_rotate(const double* v, const double* axis, double angle, double* out) {
  double temp, cross[3], cos_ang = std::cos(angle), sin_ang = std::sin(angle);
  out[0] = v[0] * cos_ang;
  out[1] = v[1] * cos_ang;
  out[2] = v[2] * cos_ang;
  temp = axis[0] * v[0] + axis[1] * v[1] + axis[2] * v[2];
  temp = temp * (1.0 - cos_ang);
  out[0] += axis[0] * temp;
  out[1] += axis[1] * temp;
  out[2] += axis[2] * temp;
  cross[0] = axis[1] * v[2] - axis[2] * v[1];
  cross[1] = axis[2] * v[0] - axis[0] * v[2];
  cross[2] = axis[0] * v[1] - axis[1] * v[0];
  out[0] += cross[0] * sin_ang;
  out[1] += cross[1] * sin_ang;
  out[2] += cross[2] * sin_ang;
}

std::size_t reference_index(double theta_in, double fi_in, double theta_out, double fi_out) {
  double in[3] = {std::sin(theta_in) * std::cos(fi_in), std::sin(theta_in) * std::sin(fi_in),
                  std::cos(theta_in)};
  double out[3] = {std::sin(theta_out) * std::cos(fi_out), std::sin(theta_out) * std::sin(fi_out),
                   std::cos(theta_out)};
  double half[3] = {(in[0] + out[0]) / 2, (in[1] + out[1]) / 2, (in[2] + out[2]) / 2};
  const double norm = std::sqrt(half[0] * half[0] + half[1] * half[1] + half[2] * half[2]);
  for (double& h : half) h /= norm;
  const double theta_half = std::acos(half[2]);
  const double fi_half = std::atan2(half[1], half[0]);
  const double bi_normal[3] = {0.0, 1.0, 0.0}, normal[3] = {0.0, 0.0, 1.0};
  double temp[3], diff[3];
  reference_rotate(in, normal, -fi_half, temp);
  reference_rotate(temp, bi_normal, -theta_half, diff);
  const double theta_diff = std::acos(diff[2]);
  double fi_diff = std::atan2(diff[1], diff[0]);
  int th;
  if (theta_half <= 0.0) {
    th = 0;
  } else {
    th = int(std::sqrt(theta_half / (kPi / 2.0) * 90 * 90));
    th = std::clamp(th, 0, 89);
  }
  int td = std::clamp(int(theta_diff / (kPi * 0.5) * 90), 0, 89);
  if (fi_diff < 0.0) fi_diff += kPi;
  int pd = std::clamp(int(fi_diff / kPi * 180), 0, 179);
  return std::size_t(pd) + 180 * (std::size_t(td) + 90 * std::size_t(th));
}

TEST(Coords, HalfDiffRoundTrip) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  double worst = 0;
  for (int n = 0; n < 20000; ++n) {
    const Vec3 wi = spherical(std::acos(u(rng)), 2 * kPi * u(rng));
    const Vec3 wo = spherical(std::acos(u(rng)), 2 * kPi * u(rng));
    const HalfDiff hd = to_half_diff(wi, wo);
    Vec3 wi2, wo2;
    from_half_diff(hd, &wi2, &wo2);
    worst = std::max({worst, std::abs(wi.x - wi2.x), std::abs(wi.y - wi2.y), std::abs(wi.z - wi2.z),
                      std::abs(wo.x - wo2.x), std::abs(wo.y - wo2.y), std::abs(wo.z - wo2.z)});
    // And the angles survive the trip back.
    const HalfDiff hd2 = to_half_diff(wi2, wo2);
    EXPECT_NEAR(hd.theta_h, hd2.theta_h, 1e-7);
    EXPECT_NEAR(hd.theta_d, hd2.theta_d, 1e-7);
  }
  EXPECT_LT(worst, 1e-12);
}

TEST(Coords, AnglesRoundTripFromHalfDiff) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.01, 0.99);
  for (int n = 0; n < 20000; ++n) {
    HalfDiff hd{u(rng) * kPi / 2, (2 * u(rng) - 1) * kPi, u(rng) * kPi / 2, (2 * u(rng) - 1) * kPi};
    Vec3 wi, wo;
    from_half_diff(hd, &wi, &wo);
    const HalfDiff back = to_half_diff(wi, wo);
    EXPECT_NEAR(back.theta_h, hd.theta_h, 1e-9);
    EXPECT_NEAR(back.theta_d, hd.theta_d, 1e-9);
    EXPECT_NEAR(std::remainder(back.phi_h - hd.phi_h, 2 * kPi), 0, 1e-9);
    EXPECT_NEAR(std::remainder(back.phi_d - hd.phi_d, 2 * kPi), 0, 1e-9);
  }
}

TEST(Coords, ReciprocityMapsPhiDByPiAndKeepsTheBin) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  for (int n = 0; n < 20000; ++n) {
    const Vec3 wi = spherical(std::acos(u(rng)), 2 * kPi * u(rng));
    const Vec3 wo = spherical(std::acos(u(rng)), 2 * kPi * u(rng));
    const HalfDiff a = to_half_diff(wi, wo), b = to_half_diff(wo, wi);
    EXPECT_NEAR(a.theta_h, b.theta_h, 1e-12);
    EXPECT_NEAR(a.theta_d, b.theta_d, 1e-12);
    EXPECT_NEAR(std::remainder(b.phi_d - a.phi_d - kPi, 2 * kPi), 0, 1e-9);
    // Same bin, except where floating point puts phi_d within rounding of a bin edge.
    const double p = phi_d_position(a.phi_d);
    if (std::abs(p - std::round(p)) > 1e-6) {
      EXPECT_EQ(nearest_bin(wi, wo), nearest_bin(wo, wi));
    }
  }
}

TEST(Coords, NearestBinMatchesReferenceReader) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  int mismatches = 0;
  for (int n = 0; n < 200000; ++n) {
    const double ti = std::acos(u(rng)), fi = 2 * kPi * u(rng);
    const double to = std::acos(u(rng)), fo = 2 * kPi * u(rng);
    mismatches +=
        nearest_bin(spherical(ti, fi), spherical(to, fo)) != reference_index(ti, fi, to, fo);
  }
  // Our half vector is normalized from (wi + wo) rather than (wi + wo) / 2: identical up to the
  // last bit, which can flip a bin only on an exact edge.
  EXPECT_LE(mismatches, 2);
}

TEST(Coords, KnownValues) {
  // Normal incidence, mirror direction: theta_h = 0, theta_d = 0.
  HalfDiff hd = to_half_diff({0, 0, 1}, {0, 0, 1});
  EXPECT_DOUBLE_EQ(hd.theta_h, 0);
  EXPECT_NEAR(hd.theta_d, 0, 1e-15);
  EXPECT_EQ(nearest_bin({0, 0, 1}, {0, 0, 1}), 0u);
  // wi at 60 deg, wo at 60 deg opposite: mirror config, h = normal, theta_d = 60 deg.
  const Vec3 wi = spherical(kPi / 3, 0), wo = spherical(kPi / 3, kPi);
  hd = to_half_diff(wi, wo);
  EXPECT_NEAR(hd.theta_h, 0, 1e-12);
  EXPECT_NEAR(hd.theta_d, kPi / 3, 1e-12);
  const int td = theta_d_index(hd.theta_d);  // exactly 60 deg, up to rounding: bin 59 or 60
  EXPECT_TRUE(td == 59 || td == 60) << td;
  // wi = wo at 40 deg: theta_h = 40 deg, theta_d = 0.
  const Vec3 w = spherical(40 * kPi / 180, 1.0);
  hd = to_half_diff(w, w);
  EXPECT_NEAR(hd.theta_h, 40 * kPi / 180, 1e-12);
  EXPECT_NEAR(hd.theta_d, 0, 1e-7);
}

TEST(Coords, GrazingAndBinEdges) {
  EXPECT_EQ(theta_h_index(0.0), 0);
  EXPECT_EQ(theta_h_index(-1e-9), 0);
  EXPECT_EQ(theta_h_index(kPi / 2), 89);
  EXPECT_EQ(theta_d_index(kPi / 2), 89);
  EXPECT_EQ(theta_d_index(0.0), 0);
  EXPECT_EQ(phi_d_index(kPi), 179);
  EXPECT_EQ(phi_d_index(-1e-12), 179);  // -0 - eps folds to just below pi
  EXPECT_EQ(phi_d_index(0.0), 0);
  // Near-grazing difference angle (at exactly 90 deg wo = -wi and h is undefined).
  HalfDiff hd{0.3, 0.2, kPi / 2 - 1e-4, 0.5};
  Vec3 wi, wo;
  from_half_diff(hd, &wi, &wo);
  EXPECT_NEAR(to_half_diff(wi, wo).theta_d, kPi / 2 - 1e-4, 1e-9);
  EXPECT_NEAR(dot(wi, wo), -1.0, 1e-7);
  // wi = -wo has no half vector; must not produce NaN.
  hd = to_half_diff({0, 0.6, 0.8}, {0, -0.6, -0.8});
  EXPECT_FALSE(std::isnan(hd.theta_h) || std::isnan(hd.theta_d) || std::isnan(hd.phi_d));
}

TEST(Coords, BinPositionsInvertBinAngles) {
  for (int i = 0; i < kThetaHBins; ++i) {
    EXPECT_NEAR(theta_h_position(theta_h_of(i)), i, 1e-12);
    // The reference index of a bin's own angle is the bin (nudged inside against rounding).
    EXPECT_EQ(theta_h_index(theta_h_of(i + 1e-9)), i);
  }
  for (int j = 0; j < kThetaDBins; ++j) EXPECT_EQ(theta_d_index(theta_d_of(j + 1e-9)), j);
  for (int k = 0; k < kPhiDBins; ++k) EXPECT_EQ(phi_d_index(phi_d_of(k + 1e-9)), k);
  EXPECT_NEAR(phi_d_position(-0.25 * kPi), 135.0, 1e-12);
}

TEST(Coords, LinearLookupEqualsTableAtBinsAndInterpolates) {
  BrdfTable t;
  for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
    const BinIndex b = merl_bin(i);
    for (int c = 0; c < 3; ++c) t.set_physical(c, i, 1.0 + b.theta_h + 0.5 * b.theta_d + 0.01 * c);
  }
  // At a bin's own angles the linear lookup returns the bin.
  for (int i : {3, 20, 50, 88}) {
    for (int j : {0, 10, 45}) {
      HalfDiff hd{theta_h_of(i), 0.0, theta_d_of(j), phi_d_of(30)};
      Vec3 wi, wo;
      from_half_diff(hd, &wi, &wo);
      double rgb[3];
      lookup_linear(t, wi, wo, rgb);
      EXPECT_NEAR(rgb[0], 1.0 + i + 0.5 * j, 1e-6);
    }
  }
  // Halfway between bins: the average (the table is linear in bin position).
  HalfDiff hd{theta_h_of(20.5), 0.0, theta_d_of(10.5), phi_d_of(30.5)};
  Vec3 wi, wo;
  from_half_diff(hd, &wi, &wo);
  double rgb[3];
  lookup_linear(t, wi, wo, rgb);
  EXPECT_NEAR(rgb[0], 1.0 + 20.5 + 0.5 * 10.5, 1e-6);
}

TEST(Coords, GridPositionMatchesHalfDiffAngles) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(0, 1);
  for (int n = 0; n < 50000; ++n) {
    const Vec3 wi = spherical(std::acos(u(rng)), 2 * kPi * u(rng));
    const Vec3 wo = n % 100 == 0 ? wi : spherical(std::acos(u(rng)), 2 * kPi * u(rng));
    const HalfDiff hd = to_half_diff(wi, wo);
    const GridPosition g = grid_position(wi, wo);
    EXPECT_NEAR(g.theta_h, theta_h_position(hd.theta_h), 1e-9);
    // At wi = wo, theta_d = acos(1 - rounding): both forms carry ~1e-8 rad of rounding noise.
    EXPECT_NEAR(g.theta_d, theta_d_position(hd.theta_d), n % 100 == 0 ? 1e-5 : 1e-9);
    // phi_d is periodic with period 180 bins; near theta_d = 0 it is undefined, so skip there.
    if (hd.theta_d > 1e-6) {
      EXPECT_NEAR(std::remainder(g.phi_d - phi_d_position(hd.phi_d), 180.0), 0, 1e-7) << n;
    }
  }
}

TEST(Coords, BelowHorizonGeometry) {
  EXPECT_FALSE(bin_below_horizon(0, 0, 0));
  EXPECT_FALSE(bin_below_horizon(0, 89, 90));  // h = n: wi and wo at 89 deg, both above
  EXPECT_TRUE(bin_below_horizon(89, 89, 0));   // h near grazing, d tilted further: below
  std::size_t below = 0;
  for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
    const BinIndex b = merl_bin(i);
    below += bin_below_horizon(b.theta_h, b.theta_d, b.phi_d);
  }
  // A substantial fraction of the grid, but far from all of it.
  EXPECT_GT(below, kBinsPerChannel / 10);
  EXPECT_LT(below, kBinsPerChannel / 2);
}

}  // namespace
}  // namespace cbrdf
