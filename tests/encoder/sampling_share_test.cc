// SPDX-License-Identifier: MIT
// Each BrdfSampler table's cosine-weighted share (sampling_share.h): broad lobes near normal
// incidence, where a piecewise-constant table does no better than cosine-weighted sampling, are
// drawn cosine-weighted; glossy lobes keep their table.
#include "sampling_share.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "cbrdf/analytic.h"
#include "cbrdf/samples.h"
#include "cbrdf/sampling.h"
#include "synthetic_model.h"

namespace cbrdf {
namespace {

constexpr double kPi = std::numbers::pi;

// A matte, fabric-like lobe: nearly constant, rising a little towards grazing directions.
void matte(const Vec3& wi, const Vec3& wo, double rgb[3]) {
  const double v = 0.06 * (1 + 0.25 * std::pow(1 - wi.z, 4)) * (1 + 0.25 * std::pow(1 - wo.z, 4));
  rgb[0] = rgb[1] = rgb[2] = v;
}

// The variance of f cos / pdf (f = `truth`) at wo under the sampler, and under cosine-weighted
// sampling from the same uniform numbers.
struct Variances {
  double sampler, cosine;
};

Variances variances(const BrdfSampler& s, const BrdfFn& truth, const Vec3& wo, int n) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double m[2] = {0, 0}, m2[2] = {0, 0};
  for (int k = 0; k < n; ++k) {
    const double u1 = u(rng), u2 = u(rng);
    const BrdfSample d = s.sample(wo, u1, u2);
    const Vec3 wc = sample_cosine_hemisphere(u1, u2);
    const Vec3 wis[2] = {d.wi, wc};
    const double pdfs[2] = {d.valid ? d.pdf : 0.0, wc.z / kPi};
    for (int i = 0; i < 2; ++i) {
      double rgb[3] = {0, 0, 0};
      if (pdfs[i] > 0) truth(wis[i], wo, rgb);
      const double x = pdfs[i] > 0 ? rgb[0] * wis[i].z / pdfs[i] : 0.0;
      m[i] += x;
      m2[i] += x * x;
    }
  }
  const auto var = [n](double s1, double s2) { return s2 / n - (s1 / n) * (s1 / n); };
  return {var(m[0], m2[0]), var(m[1], m2[1])};
}

// The regression: at normal incidence the 2.2 sampler's table of a matte lobe (built at its
// bin's central theta_o, with mass in cells that reflect normal incidence below the horizon) gave
// several times cosine-weighted sampling's variance; the share now falls back to cosine there.
TEST(SamplingShare, MatteLobeAtNormalIncidenceIsNoWorseThanCosine) {
  const Vec3 wo = testing::direction_deg(0, 0);
  SamplerSettings old_settings;
  old_settings.min_table_gain = 0;
  const Variances before = variances(BrdfSampler(matte, old_settings), matte, wo, 100000);
  const Variances after = variances(BrdfSampler(matte), matte, wo, 100000);
  std::printf(
      "[ measured ] matte lobe at normal incidence: cosine/sampler variance %.3f (2.2: %.3f)\n",
      after.cosine / after.sampler, before.cosine / before.sampler);
  EXPECT_LT(before.cosine / before.sampler, 1.0);
  EXPECT_GE(after.cosine / after.sampler, 1.0);
}

// Where the table falls back, every draw is cosine-weighted: pdf = cos / pi exactly, and the
// density sample_pdf reads agrees.
TEST(SamplingShare, AFallenBackTableDrawsCosineWeighted) {
  const BrdfSampler s(matte);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Vec3 wo = testing::direction_deg(0.5, 60);
  for (int k = 0; k < 2000; ++k) {
    const BrdfSample d = s.sample(wo, u(rng), u(rng));
    ASSERT_TRUE(d.valid);
    EXPECT_EQ(d.pdf, d.wi.z / kPi);
    EXPECT_EQ(s.sample_pdf(d.wi, wo), d.pdf);
  }
}

// A glossy lobe keeps its table at every theta_o, with the least cosine share: its density is not
// the cosine's, and its gain over cosine-weighted sampling is large.
TEST(SamplingShare, AGlossyLobeKeepsItsTable) {
  const AnalyticBrdf brdf = *sample_brdf("ggx-sharp");
  const BrdfFn f = [brdf](const Vec3& wi, const Vec3& wo, double rgb[3]) {
    brdf.eval(wi, wo, rgb);
  };
  const BrdfSampler s(f);
  for (double theta : {0.0, 30.0, 60.0, 75.0}) {
    const Vec3 wo = testing::direction_deg(theta, 10);
    const BrdfSample d = s.sample(wo, 0.5, 0.5);  // u1 >= 0.1: a table draw
    ASSERT_TRUE(d.valid) << theta;
    EXPECT_NE(d.pdf, d.wi.z / kPi) << theta;
    const Variances v = variances(s, f, wo, 20000);
    EXPECT_GT(v.cosine / v.sampler, 10.0) << theta;
  }
}

// best_cosine_share's choices on quadratures whose answers are known.
TEST(SamplingShare, BestShareOnKnownQuadratures) {
  // A Lambertian integrand g = cos / pi on a uniform grid of wi (area 4 d: d = 1/4 for each).
  std::vector<internal::QuadraturePoint> points;
  std::vector<double> cosine_pdf, exact_pdf, flat_pdf;
  const int n = 64;
  for (int i = 0; i < n; ++i) {
    const double z = (i + 0.5) / n;  // uniform in cos(theta_i): area 2 pi / n per point
    points.push_back({z / kPi, z, 0.25, 2 * kPi / n, i});
    cosine_pdf.push_back(z / kPi);
    flat_pdf.push_back(1 / (2 * kPi));  // uniform over the hemisphere
  }
  const double none[1] = {0.0};
  // A table equal to the cosine's density gains nothing: cosine-weighted only.
  EXPECT_EQ(internal::best_cosine_share(points, cosine_pdf, none, 0.1, 2.0), 1.0);
  // A uniform table is worse than cosine for a Lambertian integrand: cosine-weighted only.
  EXPECT_EQ(internal::best_cosine_share(points, flat_pdf, none, 0.1, 2.0), 1.0);
  // min_gain 0: the least share, whatever the table.
  EXPECT_EQ(internal::best_cosine_share(points, flat_pdf, none, 0.1, 0.0), 0.1);
  // An integrand the table matches and cosine does not (g = cos^3): the table, at the least share.
  std::vector<internal::QuadraturePoint> peaked = points;
  std::vector<double> peaked_pdf;
  double norm = 0;
  for (const auto& q : peaked) norm += q.wi_z * q.wi_z * q.wi_z * q.area * 4 * q.d;
  for (auto& q : peaked) {
    q.g = q.wi_z * q.wi_z * q.wi_z;
    peaked_pdf.push_back(q.g / norm);
  }
  EXPECT_EQ(internal::best_cosine_share(peaked, peaked_pdf, none, 0.1, 2.0), 0.1);
  // The same table losing half its mass below the horizon at its bin's edge: the loss costs
  // more than the table gains, and the share goes to cosine.
  const double half[2] = {0.0, 0.5};
  EXPECT_GT(internal::best_cosine_share(peaked, peaked_pdf, half, 0.1, 2.0), 0.1);
}

}  // namespace
}  // namespace cbrdf
