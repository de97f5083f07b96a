// SPDX-License-Identifier: MIT
#include "metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

namespace cbrdf {
namespace {

constexpr double kPi = std::numbers::pi;

// A table whose every bin holds a smooth function of its grid angles, channel-dependent, with the
// bins below the horizon marked not measured as in a MERL file.
BrdfTable smooth_table() {
  BrdfTable t;
  for (int h = 0; h < kThetaHBins; ++h) {
    for (int d = 0; d < kThetaDBins; ++d) {
      for (int p = 0; p < kPhiDBins; ++p) {
        const std::size_t idx = merl_index(h, d, p);
        if (bin_below_horizon(h, d, p)) {
          t.set_not_measured(idx);
          continue;
        }
        const double base = 0.2 + 3.0 * std::exp(-20 * theta_h_of(h)) +
                            0.1 * std::cos(theta_d_of(d)) + 0.05 * std::cos(phi_d_of(p));
        for (int c = 0; c < kChannels; ++c) t.set_physical(c, idx, base * (1.0 + 0.2 * c));
      }
    }
  }
  return t;
}

BrdfTable constant_table(double v) {
  BrdfTable t;
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) t.set_physical(c, i, v);
  }
  return t;
}

TEST(BrdfMetrics, IdenticalTablesHaveZeroError) {
  const BrdfTable t = smooth_table();
  const BrdfMetrics m = brdf_metrics(t, t);
  const std::size_t measured = kBinsPerChannel - t.count_not_measured() / 3;
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(m.rel_rmse[c], 0.0);
    EXPECT_EQ(m.log_rmse[c], 0.0);
    EXPECT_EQ(m.cos_rmse[c], 0.0);
    EXPECT_EQ(m.bins[c], measured);
  }
  EXPECT_LT(measured, kBinsPerChannel);  // the horizon mask is really there
}

TEST(BrdfMetrics, ScaledTableHasRelativeErrorOfTheScale) {
  const BrdfTable ref = smooth_table();
  BrdfTable test = ref;
  for (int c = 0; c < 3; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (ref.measured(c, i)) test.set_physical(c, i, ref.physical(c, i) * 1.1);
    }
  }
  const BrdfMetrics m = brdf_metrics(ref, test);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(m.rel_rmse[c], 0.1, 1e-12);
  EXPECT_NEAR(m.rel_rmse_mean, 0.1, 1e-12);
}

TEST(BrdfMetrics, ConstantTablesGiveHandComputedValues) {
  const double a = 0.7, b = 0.95;
  const BrdfMetrics m = brdf_metrics(constant_table(a), constant_table(b));
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(m.rel_rmse[c], (b - a) / a, 1e-12);
    EXPECT_NEAR(m.log_rmse[c], std::log(1 + b) - std::log(1 + a), 1e-12);
    // A weighted mean of a constant squared error is that error, whatever the weights.
    EXPECT_NEAR(m.cos_rmse[c], b - a, 1e-12);
    EXPECT_EQ(m.bins[c], kBinsPerChannel);
  }
  EXPECT_NEAR(m.log_rmse_mean, std::log(1 + b) - std::log(1 + a), 1e-12);
}

TEST(BrdfMetrics, ReferenceNotMeasuredBinsAreIgnoredTestOnesReadZero) {
  const BrdfTable ref = smooth_table();
  BrdfTable test = ref;
  // A wild value where the reference has no measurement changes nothing.
  std::size_t unmeasured = kBinsPerChannel;
  for (std::size_t i = 0; i < kBinsPerChannel && unmeasured == kBinsPerChannel; ++i) {
    if (!ref.measured(0, i)) unmeasured = i;
  }
  ASSERT_LT(unmeasured, kBinsPerChannel);
  for (int c = 0; c < 3; ++c) test.set_physical(c, unmeasured, 1e6);
  EXPECT_EQ(brdf_metrics(ref, test).rel_rmse[0], 0.0);

  // A bin the test does not measure counts as 0: the error there is the reference value itself.
  test = ref;
  const std::size_t idx = merl_index(5, 5, 5);
  ASSERT_TRUE(ref.measured(1, idx));
  test.set_stored(1, idx, -1.0);
  double sum_sq = 0;
  for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
    if (ref.measured(1, i)) sum_sq += ref.physical(1, i) * ref.physical(1, i);
  }
  const BrdfMetrics m = brdf_metrics(ref, test);
  EXPECT_NEAR(m.rel_rmse[1], ref.physical(1, idx) / std::sqrt(sum_sq), 1e-12);
  EXPECT_EQ(m.rel_rmse[0], 0.0);
  EXPECT_EQ(m.rel_rmse[2], 0.0);
}

// The documented weight: cos(theta_i) cos(theta_o) at the grid pair times the bin's measure.
double documented_weight(int h, int d, int p) {
  Vec3 wi, wo;
  from_half_diff({theta_h_of(h), 0.0, theta_d_of(d), phi_d_of(p)}, &wi, &wo);
  const double measure =
      (std::cos(theta_h_of(h)) - std::cos(theta_h_of(h + 1))) *
      (std::pow(std::sin(theta_d_of(d + 1)), 2) - std::pow(std::sin(theta_d_of(d)), 2)) / 2;
  return wi.z * wo.z * measure;
}

TEST(BrdfMetrics, CosineWeightsFollowTheDocumentedFormula) {
  const BrdfTable ref = constant_table(1.0);
  // One error of 1 in a near-normal bin, then in a grazing one; sum w is the same in both runs,
  // so the ratio of the squared metrics is the ratio of the two bins' weights.
  auto cos_rmse_with_error_at = [&](int h, int d, int p) {
    BrdfTable test = ref;
    for (int c = 0; c < 3; ++c) test.set_physical(c, merl_index(h, d, p), 2.0);
    return brdf_metrics(ref, test).cos_rmse[0];
  };
  const double near_normal = cos_rmse_with_error_at(30, 10, 90);
  const double grazing = cos_rmse_with_error_at(30, 80, 90);
  EXPECT_GT(near_normal, grazing);
  EXPECT_NEAR(near_normal * near_normal / (grazing * grazing),
              documented_weight(30, 10, 90) / documented_weight(30, 80, 90), 1e-9);
}

TEST(BrdfMetrics, CallableIsEvaluatedAtEachBinsGridDirections) {
  // The same function of the bin angles as a table and as a callable of directions. The phi_d term
  // vanishes where phi_d is undefined (theta_h = 0 or theta_d = 0) and has period pi (reciprocity).
  auto value = [](double th, double td, double pd) {
    return 0.5 + std::exp(-10 * th) + 0.3 * td +
           0.1 * std::sin(th) * std::sin(td) * std::cos(2 * pd);
  };
  BrdfTable ref;
  for (int h = 0; h < kThetaHBins; ++h) {
    for (int d = 0; d < kThetaDBins; ++d) {
      for (int p = 0; p < kPhiDBins; ++p) {
        const double v = value(theta_h_of(h), theta_d_of(d), phi_d_of(p));
        for (int c = 0; c < 3; ++c) ref.set_physical(c, merl_index(h, d, p), v * (c + 1));
      }
    }
  }
  const BrdfFn fn = [&value](const Vec3& wi, const Vec3& wo, double rgb[3]) {
    const HalfDiff hd = to_half_diff(wi, wo);
    const double v = value(hd.theta_h, hd.theta_d, hd.phi_d);
    for (int c = 0; c < 3; ++c) rgb[c] = v * (c + 1);
  };
  const BrdfMetrics m = brdf_metrics(ref, fn);
  for (int c = 0; c < 3; ++c) EXPECT_LT(m.rel_rmse[c], 1e-7);
  // And a callable that is off by 5 % everywhere is measured as such.
  const BrdfFn off = [&fn](const Vec3& wi, const Vec3& wo, double rgb[3]) {
    fn(wi, wo, rgb);
    for (int c = 0; c < 3; ++c) rgb[c] *= 0.95;
  };
  EXPECT_NEAR(brdf_metrics(ref, off).rel_rmse[2], 0.05, 1e-7);
}

// ---- Sphere renders ----

// Pixel centre and normal, as documented in metrics.h.
Vec3 normal_at(int x, int y, int size) {
  const double u = (x + 0.5) / size * 2 - 1, v = 1 - (y + 0.5) / size * 2;
  return {u, v, std::sqrt(std::max(0.0, 1 - u * u - v * v))};
}

BrdfFn constant_fn(double r, double g, double b) {
  return [r, g, b](const Vec3&, const Vec3&, double rgb[3]) {
    rgb[0] = r;
    rgb[1] = g;
    rgb[2] = b;
  };
}

TEST(RenderSphere, LambertianRadianceAtHandPickedPixels) {
  const double rho = 0.8;
  const Image img = render_sphere(constant_fn(rho / kPi, rho / kPi / 2, 0), 45.0, 256);
  ASSERT_EQ(img.width, 256);
  ASSERT_EQ(img.height, 256);
  const double s = std::sqrt(0.5);  // sin 45 = cos 45
  // Pixel (128, 128): u = 1/256, v = -1/256.
  const double u = 1.0 / 256, z = std::sqrt(1 - 2.0 / 65536);
  EXPECT_NEAR(img.at(128, 128, 0), rho / kPi * (u * s + z * s), 1e-6);
  EXPECT_NEAR(img.at(128, 128, 1), rho / kPi / 2 * (u * s + z * s), 1e-6);
  EXPECT_EQ(img.at(128, 128, 2), 0.0f);
  // Pixel (200, 60): u = 401/256 - 1, v = 1 - 121/256.
  const double u2 = 401.0 / 256 - 1, v2 = 1 - 121.0 / 256, z2 = std::sqrt(1 - u2 * u2 - v2 * v2);
  EXPECT_NEAR(img.at(200, 60, 0), rho / kPi * (u2 * s + z2 * s), 1e-6);
  // Corner: outside the sphere, background 0.
  EXPECT_EQ(img.at(0, 0, 0), 0.0f);
  EXPECT_EQ(img.at(255, 255, 1), 0.0f);
}

TEST(RenderSphere, EveryPixelMatchesLambertAndTheTerminatorIsWhereItShouldBe) {
  const double a = 75.0 * kPi / 180;
  const Vec3 light{std::sin(a), 0, std::cos(a)};
  const int size = 256;
  const Image img = render_sphere(constant_fn(1 / kPi, 1 / kPi, 1 / kPi), 75.0, size);
  const std::vector<std::uint8_t> mask = sphere_mask(size);
  int lit = 0, dark = 0;
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const double u = (x + 0.5) / size * 2 - 1, v = 1 - (y + 0.5) / size * 2;
      const bool inside = u * u + v * v < 1;
      ASSERT_EQ(mask[std::size_t(y) * size + x] != 0, inside) << x << "," << y;
      const double cos_i = inside ? dot(light, normal_at(x, y, size)) : 0.0;
      const double expected = cos_i > 0 ? cos_i / kPi : 0.0;
      ASSERT_NEAR(img.at(x, y, 0), expected, 1e-6) << x << "," << y;
      (expected > 0 ? lit : dark) += inside ? 1 : 0;
    }
  }
  EXPECT_GT(lit, 0);
  EXPECT_GT(dark, 0);
  // On row 128 (v = -1/256) the terminator is at u = -sqrt(1 - v^2) cos 75 = -0.25882: pixel 94
  // (u = -0.26172) is dark, pixel 95 (u = -0.25391) is lit.
  EXPECT_EQ(img.at(94, 128, 0), 0.0f);
  EXPECT_GT(img.at(95, 128, 0), 0.0f);
  for (int x = 0; x <= 94; ++x) EXPECT_EQ(img.at(x, 128, 0), 0.0f);
}

TEST(RenderSphere, DirectionsAreInOneLocalFrame) {
  const double a_deg = 45.0, a = a_deg * kPi / 180;
  const int size = 64;
  // dot(wi, wo) is the cosine of the light-view angle in any frame; wo.z is the normal's z.
  const BrdfFn f = [](const Vec3& wi, const Vec3& wo, double rgb[3]) {
    rgb[0] = dot(wi, wo);
    rgb[1] = wo.z;
    rgb[2] = wi.z;
  };
  const Image img = render_sphere(f, a_deg, size, 3);
  const Vec3 light{std::sin(a), 0, std::cos(a)};
  int lit = 0;
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const Vec3 n = normal_at(x, y, size);
      const double cos_i = dot(light, n);
      if (img.at(x, y, 0) == 0.0f) continue;
      ASSERT_GT(cos_i, 0.0);
      ++lit;
      EXPECT_NEAR(img.at(x, y, 0), std::cos(a) * cos_i, 1e-6);
      EXPECT_NEAR(img.at(x, y, 1), n.z * cos_i, 1e-6);
      EXPECT_NEAR(img.at(x, y, 2), cos_i * cos_i, 1e-6);
    }
  }
  EXPECT_GT(lit, 2000);  // of about 3200 pixels inside the sphere
}

TEST(RenderSphere, ThreadCountDoesNotChangeTheImage) {
  const BrdfTable t = smooth_table();
  const BrdfFn f = nearest_lookup_fn(t);
  EXPECT_EQ(render_sphere(f, 45.0, 128, 1), render_sphere(f, 45.0, 128, 5));
}

TEST(RenderSphere, TableOverloadEqualsTheLookupFunctionBitForBit) {
  const BrdfTable t = smooth_table();  // with the horizon mask
  for (double a : {10.0, 45.0, 75.0, 89.0}) {
    const Image by_fn = render_sphere(nearest_lookup_fn(t), a, 96);
    EXPECT_EQ(render_sphere(t, a, 96), by_fn) << a;
    EXPECT_EQ(render_sphere(t, a, 96), by_fn) << a;  // from the cache this time
  }
  // The cache is keyed by size too.
  EXPECT_EQ(render_sphere(t, 45.0, 50), render_sphere(nearest_lookup_fn(t), 45.0, 50));
}

TEST(RenderSphere, OutOfRangeArgumentsGiveEmptyOrBlackImages) {
  const BrdfTable t = constant_table(1.0);
  EXPECT_TRUE(render_sphere(t, 45.0, 0).empty());
  EXPECT_TRUE(render_sphere(nearest_lookup_fn(t), 45.0, kMaxSphereSize + 1).empty());
  EXPECT_TRUE(sphere_mask(-3).empty());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Image black(16, 16);
  EXPECT_EQ(render_sphere(t, nan, 16), black);
  EXPECT_EQ(render_sphere(nearest_lookup_fn(t), nan, 16), black);
  // A light from behind the sphere lights nothing.
  EXPECT_EQ(render_sphere(t, 180.0, 16), black);
}

TEST(RenderSphere, NotMeasuredBinsReadAsZero) {
  // Every bin measured at 1.5 (physical) except theta_h bins >= 40, which are not measured.
  BrdfTable t = constant_table(1.5);
  for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
    if (merl_bin(i).theta_h >= 40) t.set_not_measured(i, -1.0);
  }
  const int size = 128;
  const double a = 45.0 * kPi / 180;
  const Image img = render_sphere(nearest_lookup_fn(t), 45.0, size);
  EXPECT_EQ(render_sphere(t, 45.0, size), img);
  const Vec3 light{std::sin(a), 0, std::cos(a)};
  // The half vector is frame independent: theta_h is its angle to the normal.
  const Vec3 hv{std::sin(a) / std::sqrt(2 + 2 * std::cos(a)), 0,
                (1 + std::cos(a)) / std::sqrt(2 + 2 * std::cos(a))};
  int zeros = 0, values = 0;
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const double u = (x + 0.5) / size * 2 - 1, v = 1 - (y + 0.5) / size * 2;
      if (u * u + v * v >= 1) continue;
      const Vec3 n = normal_at(x, y, size);
      const double cos_i = dot(light, n);
      if (cos_i <= 0) continue;
      const double pos = theta_h_position(std::acos(std::min(1.0, dot(n, hv))));
      if (std::abs(pos - 40) < 1e-3) continue;  // too close to the bin edge to call
      if (pos > 40) {
        EXPECT_EQ(img.at(x, y, 0), 0.0f) << x << "," << y;
        ++zeros;
      } else {
        EXPECT_NEAR(img.at(x, y, 0), 1.5 * cos_i, 1e-5) << x << "," << y;
        ++values;
      }
    }
  }
  EXPECT_GT(zeros, 100);
  EXPECT_GT(values, 100);
}

// ---- PSNR and tone mapping ----

TEST(SpherePsnr, IdenticalBrdfsGiveTheCap) {
  const BrdfTable t = smooth_table();
  const ImageMetrics m = sphere_psnr(nearest_lookup_fn(t), nearest_lookup_fn(t));
  EXPECT_EQ(m.psnr_linear, kPsnrCapDb);
  EXPECT_EQ(m.psnr_tonemapped, kPsnrCapDb);
  ASSERT_EQ(m.per_light.size(), 3u);
  EXPECT_EQ(m.per_light[2].light_angle_deg, 75.0);
  const BrdfTable copy = t;
  const ImageMetrics tables = sphere_psnr(t, copy);
  EXPECT_EQ(tables.psnr_linear, kPsnrCapDb);
  EXPECT_EQ(tables.psnr_tonemapped, kPsnrCapDb);
}

TEST(SpherePsnr, TableOverloadsAgreeWithTheFunctionOverload) {
  const BrdfTable ref = smooth_table();
  BrdfTable test = ref;
  for (std::size_t i = 0; i < kBinsPerChannel; i += 7) {
    if (test.measured(0, i)) test.set_physical(0, i, test.physical(0, i) * 1.3);
  }
  const ImageMetrics by_fn = sphere_psnr(nearest_lookup_fn(ref), nearest_lookup_fn(test));
  const ImageMetrics by_table = sphere_psnr(ref, test);
  const ImageMetrics mixed = sphere_psnr(ref, nearest_lookup_fn(test));
  EXPECT_LT(by_fn.psnr_linear, kPsnrCapDb);
  EXPECT_EQ(by_table.psnr_linear, by_fn.psnr_linear);
  EXPECT_EQ(by_table.psnr_tonemapped, by_fn.psnr_tonemapped);
  EXPECT_EQ(mixed.psnr_linear, by_fn.psnr_linear);
  // Only red changed: green and blue stay at the cap.
  EXPECT_LT(by_table.per_light[1].psnr_linear[0], kPsnrCapDb);
  EXPECT_EQ(by_table.per_light[1].psnr_linear[1], kPsnrCapDb);
  EXPECT_EQ(by_table.per_light[1].psnr_linear[2], kPsnrCapDb);
}

TEST(SpherePsnr, ConstantRadianceOffsetGivesHandComputedPsnr) {
  // Head-on light: every sphere pixel is lit. The test BRDF adds delta / cos(theta_i), so every
  // test pixel is the reference plus exactly delta: MSE = delta^2. The brightest reference pixel is
  // a centre pixel, (u, v) = (+-1/256, +-1/256): peak = rho/pi * sqrt(1 - 2/256^2).
  const double rho = 0.6, delta = 0.01;
  const BrdfFn ref = constant_fn(rho / kPi, rho / kPi, rho / kPi);
  const BrdfFn test = [&](const Vec3& wi, const Vec3&, double rgb[3]) {
    for (int c = 0; c < 3; ++c) rgb[c] = rho / kPi + delta / wi.z;
  };
  SphereSetup setup;
  setup.light_angles_deg = {0.0};
  const ImageMetrics m = sphere_psnr(ref, test, setup);
  const double peak = rho / kPi * std::sqrt(1 - 2.0 / 65536);
  const double expected = 10 * std::log10(peak * peak / (delta * delta));  // 25.61 dB
  EXPECT_NEAR(m.psnr_linear, expected, 1e-4);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(m.per_light[0].psnr_linear[c], expected, 1e-4);
  EXPECT_LT(m.psnr_tonemapped, kPsnrCapDb);
}

TEST(Psnr, HandComputedMaskedAndCapped) {
  Image a(2, 2), b(2, 2);
  for (float& v : a.data) v = 0.5f;
  b = a;
  b.at(0, 0, 0) = 0.75f;  // error 0.25 in one of 4 pixels: MSE = 0.015625
  EXPECT_NEAR(psnr(a, b, 0, 1.0), 10 * std::log10(1 / 0.015625), 1e-9);
  EXPECT_EQ(psnr(a, b, 1, 1.0), kPsnrCapDb);
  const std::vector<std::uint8_t> mask = {1, 0, 0, 0};  // only the differing pixel: MSE = 0.0625
  EXPECT_NEAR(psnr(a, b, 0, 2.0, &mask), 10 * std::log10(4 / 0.0625), 1e-9);
  const std::vector<std::uint8_t> other = {0, 1, 1, 1};
  EXPECT_EQ(psnr(a, b, 0, 1.0, &other), kPsnrCapDb);
  EXPECT_TRUE(std::isnan(psnr(a, Image(3, 2), 0, 1.0)));
}

TEST(Tonemap, NinetyNinthPercentileMapsToOne) {
  // Pixel i holds i + 1 in every channel: 300 values 1,1,1,2,2,2,...,100,100,100. Rank 0.99 * 299
  // = 296.01 lies between sorted values 296 (= 99) and 297 (= 100): p99 = 99.01.
  Image img(100, 1);
  for (int x = 0; x < 100; ++x) {
    for (int c = 0; c < 3; ++c) img.at(x, 0, c) = float(x + 1);
  }
  EXPECT_NEAR(percentile(img, 99.0), 99.01, 1e-9);
  const double exposure = tonemap_exposure(img);
  EXPECT_NEAR(exposure, 1 / 99.01, 1e-12);
  Image probe(3, 1);
  probe.at(0, 0, 0) = 99.01f;
  probe.at(1, 0, 0) = 49.505f;
  probe.at(2, 0, 0) = 500.0f;
  probe.at(2, 0, 1) = -3.0f;
  const Image tm = tonemap(probe, exposure);
  EXPECT_NEAR(tm.at(0, 0, 0), 1.0, 1e-6);
  EXPECT_NEAR(tm.at(1, 0, 0), std::pow(0.5, 1 / 2.2), 1e-6);
  EXPECT_EQ(tm.at(2, 0, 0), 1.0f);  // clamped
  EXPECT_EQ(tm.at(2, 0, 1), 0.0f);

  // With a mask only the counted pixels matter: pixels 0..9 -> 30 values 1..10, rank 28.71.
  std::vector<std::uint8_t> mask(100, 0);
  for (int x = 0; x < 10; ++x) mask[x] = 1;
  EXPECT_NEAR(percentile(img, 99.0, &mask), 10.0, 1e-9);
  EXPECT_NEAR(percentile(img, 50.0, &mask), 5.5, 1e-9);  // rank 14.5: between 5 and 6
}

TEST(Tonemap, SphereExposureComesFromTheReference) {
  const BrdfTable t = smooth_table();
  SphereSetup setup;
  setup.size = 64;
  setup.light_angles_deg = {30.0};
  const ImageMetrics m = sphere_psnr(nearest_lookup_fn(t), constant_fn(0, 0, 0), setup);
  const Image ref = render_sphere(nearest_lookup_fn(t), 30.0, 64);
  const std::vector<std::uint8_t> mask = sphere_mask(64);
  EXPECT_NEAR(m.per_light[0].exposure, 1.0 / percentile(ref, 99.0, &mask), 1e-12);
  // Against black, a tone-mapped channel's MSE is the mean of its squared display values.
  const Image tm = tonemap(ref, m.per_light[0].exposure);
  double sum = 0;
  int n = 0;
  for (std::size_t i = 0; i < tm.pixel_count(); ++i) {
    if (!mask[i]) continue;
    sum += double(tm.data[i * 3]) * tm.data[i * 3];
    ++n;
  }
  EXPECT_NEAR(m.per_light[0].psnr_tonemapped[0], 10 * std::log10(1.0 / (sum / n)), 1e-9);
}

TEST(DifferenceImage, ViridisScaleAndMask) {
  const std::array<float, 3> lo = viridis(0.0), hi = viridis(1.0), mid = viridis(0.5);
  EXPECT_NEAR(lo[0], 68 / 255.0, 1e-6);
  EXPECT_NEAR(lo[2], 84 / 255.0, 1e-6);
  EXPECT_NEAR(hi[0], 253 / 255.0, 1e-6);
  EXPECT_NEAR(hi[1], 231 / 255.0, 1e-6);
  // t = 0.5 is halfway between stops 4 (#26828e) and 5 (#1f9e89).
  EXPECT_NEAR(mid[1], (130 + 158) / 2 / 255.0, 1e-6);
  Image a(3, 1), b(3, 1);
  b.at(1, 0, 0) = 0.3f;  // mean |a - b| = 0.1 = scale
  b.at(2, 0, 0) = 0.15f;
  b.at(2, 0, 1) = -0.15f;  // mean 0.1 too, but masked out
  const std::vector<std::uint8_t> mask = {1, 1, 0};
  const Image d = difference_image(a, b, 0.1, &mask);
  ASSERT_EQ(d.width, 3);
  EXPECT_NEAR(d.at(0, 0, 0), lo[0], 1e-6);
  EXPECT_NEAR(d.at(1, 0, 1), hi[1], 1e-6);
  EXPECT_EQ(d.at(2, 0, 0), 0.0f);
  EXPECT_EQ(d.at(2, 0, 1), 0.0f);
  EXPECT_TRUE(difference_image(a, Image(2, 1), 0.1).empty());
  EXPECT_TRUE(difference_image(a, b, 0.0).empty());
}

}  // namespace
}  // namespace cbrdf
