// SPDX-License-Identifier: MIT
// A rejected draw's wi, exactly (0, 0, 0), passes straight back into evaluation (issue 42): eval,
// eval_f32, every batch form and sample_pdf give 0 for it, never NaN, on every path (the usual
// unit input, a batch with directions to rescale or refuse, the scalar fallback); any other
// direction that is not a unit vector is still NaN. And sample_pdf(wi, wo) is the density of what
// sample() draws, in eval's order, with the deprecated pdf(wo, wi) its mirror image.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <numbers>
#include <vector>

#include "cbrdf/model.h"
#include "cbrdf/sampling.h"
#include "synthetic_model.h"

namespace cbrdf {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool all_zero(const double* rgb) {
  return rgb[0] == 0.0 && rgb[1] == 0.0 && rgb[2] == 0.0;
}

TEST(RejectedDraw, ZeroVectorEvaluatesToZeroNotNaN) {
  const ModelEvaluator& e = testing::peaked_evaluator();
  const BrdfSampler s = make_model_sampler(e);
  const Vec3 wo = testing::direction_deg(30, 20), wi = testing::direction_deg(40, 200);
  for (const Vec3& zero : {Vec3{0, 0, 0}, Vec3{-0.0, 0.0, -0.0}}) {
    double rgb[3] = {kNaN, kNaN, kNaN};
    e.eval(zero, wo, rgb);
    EXPECT_TRUE(all_zero(rgb)) << rgb[0];
    e.eval(wi, zero, rgb);
    EXPECT_TRUE(all_zero(rgb)) << rgb[0];
    // With the other direction to rescale: the scalar fallback path.
    e.eval(zero, Vec3{wo.x * 1.0004, wo.y * 1.0004, wo.z * 1.0004}, rgb);
    EXPECT_TRUE(all_zero(rgb)) << rgb[0];
    const float zf[3] = {float(zero.x), float(zero.y), float(zero.z)};
    const float wof[3] = {float(wo.x), float(wo.y), float(wo.z)};
    float rgbf[3] = {1, 1, 1};
    e.eval_f32(zf, wof, rgbf);
    EXPECT_TRUE(rgbf[0] == 0 && rgbf[1] == 0 && rgbf[2] == 0) << rgbf[0];
    e.eval_f32(wof, zf, rgbf);
    EXPECT_TRUE(rgbf[0] == 0 && rgbf[1] == 0 && rgbf[2] == 0) << rgbf[0];
    EXPECT_EQ(s.sample_pdf(zero, wo), 0.0);
    EXPECT_EQ(s.sample_pdf(wi, zero), 0.0);
  }
  // Anything else short of unit length is still refused, the tiniest vectors included.
  for (const Vec3& bad : {Vec3{0, 0, 1e-3}, Vec3{1e-200, 0, 0}, Vec3{0, 0, 1e-170}}) {
    double rgb[3];
    e.eval(bad, wo, rgb);
    EXPECT_TRUE(std::isnan(rgb[0]) && std::isnan(rgb[1]) && std::isnan(rgb[2]));
    EXPECT_TRUE(std::isnan(s.sample_pdf(bad, wo)));
    EXPECT_TRUE(std::isnan(s.sample_pdf(wi, bad)));
  }
}

// Pairs k of a batch: unit directions, with (0, 0, 0) as wi every 7th pair and as wo every 11th;
// with `rescaled`, every 5th wi 1.0004 long (the batch's checked path) and pair 3 invalid.
struct Pairs {
  std::vector<double> wi, wo;
};

Pairs make_pairs(std::size_t n, bool rescaled) {
  Pairs p{std::vector<double>(3 * n), std::vector<double>(3 * n)};
  for (std::size_t k = 0; k < n; ++k) {
    Vec3 i = testing::direction_deg(double(k * 7 % 95), double(k * 31 % 360));
    const Vec3 o = testing::direction_deg(double(k * 13 % 91), double(k * 17 % 360));
    if (rescaled && k % 5 == 0) i = Vec3{i.x * 1.0004, i.y * 1.0004, i.z * 1.0004};
    if (k % 7 == 0) i = Vec3{0, 0, 0};
    const double iv[3] = {i.x, i.y, i.z}, ov[3] = {o.x, o.y, k % 11 == 0 ? 0.0 : o.z};
    for (int c = 0; c < 3; ++c) {
      p.wi[3 * k + c] = iv[c];
      p.wo[3 * k + c] = k % 11 == 0 ? 0.0 : ov[c];
    }
  }
  if (rescaled) p.wi[3 * 3 + 2] = 2.0;
  return p;
}

TEST(RejectedDraw, BatchesGiveZeroForZeroRowsAndEqualEvalElsewhere) {
  const ModelEvaluator& e = testing::peaked_evaluator();
  constexpr std::size_t kN = 5000;  // more than two of the batch's 2048-pair chunks
  for (const bool rescaled : {false, true}) {
    const Pairs p = make_pairs(kN, rescaled);
    std::vector<double> rgb(3 * kN), r(kN), g(kN), b(kN);
    e.eval_batch(kN, p.wi.data(), p.wo.data(), rgb.data());
    std::vector<double> soa[6];
    for (int a = 0; a < 6; ++a) {
      soa[a].resize(kN);
      for (std::size_t k = 0; k < kN; ++k) soa[a][k] = (a < 3 ? p.wi : p.wo)[3 * k + a % 3];
    }
    e.eval_batch(kN, soa[0].data(), soa[1].data(), soa[2].data(), soa[3].data(), soa[4].data(),
                 soa[5].data(), r.data(), g.data(), b.data());
    std::vector<float> fi(p.wi.begin(), p.wi.end()), fo(p.wo.begin(), p.wo.end()), frgb(3 * kN);
    e.eval_batch_f32(kN, fi.data(), fo.data(), frgb.data());
    int zero_rows = 0;
    for (std::size_t k = 0; k < kN; ++k) {
      const Vec3 i{p.wi[3 * k], p.wi[3 * k + 1], p.wi[3 * k + 2]};
      const Vec3 o{p.wo[3 * k], p.wo[3 * k + 1], p.wo[3 * k + 2]};
      double ref[3];
      e.eval(i, o, ref);
      float reff[3];
      e.eval_f32(&fi[3 * k], &fo[3 * k], reff);
      const bool zero = k % 7 == 0 || k % 11 == 0;
      zero_rows += zero;
      if (zero) {
        EXPECT_TRUE(all_zero(ref)) << k;
      } else if (rescaled && k == 3) {
        EXPECT_TRUE(std::isnan(ref[0])) << k;
      }
      const double soa_k[3] = {r[k], g[k], b[k]};
      for (int c = 0; c < 3; ++c) {
        // Bit for bit (NaN for the invalid pair alike).
        EXPECT_EQ(std::memcmp(&rgb[3 * k + c], &ref[c], sizeof(double)), 0) << k << " " << c;
        EXPECT_EQ(std::memcmp(&soa_k[c], &ref[c], sizeof(double)), 0) << k << " " << c;
        EXPECT_EQ(std::memcmp(&frgb[3 * k + c], &reff[c], sizeof(float)), 0) << k << " " << c;
      }
    }
    EXPECT_GT(zero_rows, 1000);
  }
}

TEST(RejectedDraw, DrawsPassStraightBackIntoEvalAndSamplePdf) {
  const ModelEvaluator& e = testing::peaked_evaluator();
  const BrdfSampler s = make_model_sampler(e);
  constexpr std::size_t kN = 20000;
  std::vector<double> wo(3 * kN), u(2 * kN), wi(3 * kN), pdf(kN), weight(3 * kN), f(3 * kN);
  for (std::size_t k = 0; k < kN; ++k) {
    // 16 elevations up to 89 degrees, the azimuth varied.
    const Vec3 o = testing::direction_deg(89.0 * double(k % 16) / 15, double(k * 37 % 360));
    wo[3 * k] = o.x;
    wo[3 * k + 1] = o.y;
    wo[3 * k + 2] = o.z;
    u[2 * k] = std::fmod(double(k) * 0.6180339887498949, 1.0);
    u[2 * k + 1] = std::fmod(double(k) * 0.7548776662466927, 1.0);
  }
  s.sample_batch(kN, wo.data(), u.data(), wi.data(), pdf.data(), weight.data(), 1);
  e.eval_batch(kN, wi.data(), wo.data(), f.data());
  std::size_t rejected = 0;
  for (std::size_t k = 0; k < kN; ++k) {
    const Vec3 i{wi[3 * k], wi[3 * k + 1], wi[3 * k + 2]};
    const Vec3 o{wo[3 * k], wo[3 * k + 1], wo[3 * k + 2]};
    const double p = s.sample_pdf(i, o);
    ASSERT_FALSE(std::isnan(p) || std::isnan(f[3 * k]) || std::isnan(f[3 * k + 1]) ||
                 std::isnan(f[3 * k + 2]))
        << k;
    if (pdf[k] == 0) {
      ++rejected;
      EXPECT_TRUE(i.x == 0 && i.y == 0 && i.z == 0) << k;
      EXPECT_EQ(p, 0.0) << k;
      EXPECT_TRUE(all_zero(&f[3 * k])) << k;
    } else {
      EXPECT_EQ(p, pdf[k]) << k;  // the density of what was drawn, in (wi, wo) order
    }
  }
  // Grazing elevations reject a share of their draws (reflected below the horizon).
  EXPECT_GT(rejected, 0u);
  EXPECT_LT(rejected, kN / 2);
}

TEST(RejectedDraw, DeprecatedPdfIsSamplePdfWithTheArgumentsSwapped) {
  const BrdfSampler s = make_model_sampler(testing::peaked_evaluator());
  int differ = 0;
  for (int k = 0; k < 64; ++k) {
    const Vec3 a = testing::direction_deg(5 + k % 80, k * 47 % 360),
               b = testing::direction_deg(3 + k * 7 % 85, k * 29 % 360);
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"
    const double old = s.pdf(b, a);  // pdf(wo, wi)
#pragma GCC diagnostic pop
    EXPECT_EQ(old, s.sample_pdf(a, b));
    differ += s.sample_pdf(a, b) != s.sample_pdf(b, a);
  }
  // The density is not symmetric: swapping wi and wo changes it, so the order matters.
  EXPECT_GT(differ, 48);
}

}  // namespace
}  // namespace cbrdf
