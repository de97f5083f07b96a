// SPDX-License-Identifier: MIT
// The noise estimate (noise.h): on synthetic tables with known noise, and on real materials made
// noisy at test time by ../shared/tools/make-merl.sh --noise at 1%, 3% and 5% (the clean table is
// the truth): the estimate within 25% of the noise injected, near zero on the clean tables, the
// growth towards grazing angles, and the PSNR ceiling against the real PSNR of the noisy table.
#include "cbrdf/noise.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <random>
#include <regex>
#include <string>

#include "cbrdf/coords.h"
#include "cbrdf/merl_io.h"
#include "metrics.h"
#include "test_support.h"

namespace cbrdf {
namespace {
namespace fs = std::filesystem;

// A smooth table: a lobe in theta_h on a diffuse floor, tinted per channel, and the
// below-horizon bins not measured.
BrdfTable smooth_table() {
  BrdfTable t;
  for (int th = 0; th < kThetaHBins; ++th) {
    for (int td = 0; td < kThetaDBins; ++td) {
      for (int p = 0; p < kPhiDBins; ++p) {
        const std::size_t i = merl_index(th, td, p);
        if (bin_below_horizon(th, td, p)) {
          t.set_not_measured(i);
          continue;
        }
        const double h = th / 90.0, d = td / 90.0, f = p / 180.0;
        for (int c = 0; c < kChannels; ++c) {
          const double v = (0.2 + 0.1 * c) * (1 + 0.3 * std::cos(3.1 * f) + 0.5 * d * d) +
                           20 * std::exp(-h * h / 0.01);
          t.set_physical(c, i, v);
        }
      }
    }
  }
  return t;
}

// The injected sigma averaged over a band's theta_d bins.
double band_mean_sigma(double sigma, double grazing, int band) {
  double s = 0;
  for (int td = band * kNoiseBandDegrees; td < (band + 1) * kNoiseBandDegrees; ++td) {
    const double d = td / 90.0;
    s += sigma * (1 + grazing * d * d * d * d);
  }
  return s / kNoiseBandDegrees;
}

TEST(Noise, SmoothTableIsNoiseFree) {
  const NoiseEstimate e = estimate_noise(smooth_table());
  for (double s : e.sigma) EXPECT_LT(s, kNoiseFreeSigma / 4);
  EXPECT_FALSE(e.noisy());
  EXPECT_EQ(e.psnr_ceiling_tonemapped, kPsnrCapDb);
  EXPECT_GT(e.samples, kBinsPerChannel);
}

TEST(Noise, SyntheticNoiseIsMeasuredPerChannelAndBand) {
  const BrdfTable clean = smooth_table();
  for (double sigma : {0.005, 0.02, 0.08}) {
    SCOPED_TRACE(sigma);
    const NoiseEstimate e =
        estimate_noise(testing::with_noise(clean, sigma, 7, 0), {.ceiling = false});
    EXPECT_TRUE(e.noisy());
    for (double s : e.sigma) EXPECT_NEAR(s, sigma, 0.05 * sigma);
    for (const auto& b : e.band_sigma) {
      for (double s : b) EXPECT_NEAR(s, sigma, 0.1 * sigma);
    }
    EXPECT_NEAR(e.grazing_growth, 1.0, 0.1);
  }
}

TEST(Noise, GrowthTowardsGrazingAngles) {
  const NoiseEstimate e =
      estimate_noise(testing::with_noise(smooth_table(), 0.02, 11, 3), {.ceiling = false});
  for (int b = 0; b < kNoiseBands; ++b) {
    SCOPED_TRACE(b);
    const double want = band_mean_sigma(0.02, 3, b);
    for (double s : e.band_sigma[std::size_t(b)]) EXPECT_NEAR(s, want, 0.1 * want);
  }
  EXPECT_GT(e.grazing_growth, 2.5);
}

TEST(Noise, OneNoisyChannel) {
  BrdfTable t = smooth_table();
  const BrdfTable noisy = testing::with_noise(t, 0.04, 3, 0);
  // Only green carries noise.
  std::copy(noisy.channel_data(1), noisy.channel_data(1) + kBinsPerChannel, t.channel_data(1));
  const NoiseEstimate e = estimate_noise(t, {.ceiling = false});
  EXPECT_LT(e.sigma[0], kNoiseFreeSigma / 4);
  EXPECT_NEAR(e.sigma[1], 0.04, 0.002);
  EXPECT_LT(e.sigma[2], kNoiseFreeSigma / 4);
}

// A table measured nowhere has no estimate (and no division by zero).
TEST(Noise, NothingMeasured) {
  BrdfTable t;
  for (std::size_t i = 0; i < kBinsPerChannel; ++i) t.set_not_measured(i);
  const NoiseEstimate e = estimate_noise(t);
  EXPECT_EQ(e.max_sigma(), 0.0);
  EXPECT_FALSE(e.noisy());
  EXPECT_EQ(e.samples, 0u);
}

TEST(Noise, SmoothedTargetRemovesNoiseKeepsSignal) {
  const BrdfTable clean = smooth_table();
  const BrdfTable noisy = testing::with_noise(clean, 0.03, 5, 0);
  // A base that misses the signal by a smooth 10% ramp: the smoothed target must restore it.
  BrdfTable base = clean;
  for (int c = 0; c < kChannels; ++c) {
    double* v = base.channel_data(c);
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (v[i] >= 0) v[i] *= 1 + 0.1 * merl_bin(i).theta_d / 90.0;
    }
  }
  const BrdfTable target = smooth_residual_target(noisy, base, 1e-4, 2.0);
  const BrdfMetrics to_truth = brdf_metrics(clean, target);
  const BrdfMetrics noisy_to_truth = brdf_metrics(clean, noisy);
  const BrdfMetrics base_to_truth = brdf_metrics(clean, base);
  EXPECT_LT(to_truth.rel_rmse_mean, noisy_to_truth.rel_rmse_mean / 4);
  EXPECT_LT(to_truth.rel_rmse_mean, base_to_truth.rel_rmse_mean / 4);
  // Not-measured bins are kept bit for bit.
  for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
    if (noisy.stored(0, i) < 0) {
      ASSERT_EQ(target.stored(0, i), noisy.stored(0, i));
    }
  }
}

// ---- Real materials made noisy at test time ----

// A few materials of different kinds (a fabric, a chrome, a paint) keep the test short.
const std::vector<std::string> kMaterials = {"beige-fabric", "chrome-steel", "gold-metallic-paint"};

#define CBRDF_NOISY_DIR_OR_SKIP(dir, sigma)                                                    \
  const fs::path dir = testing::noisy_materials_dir(sigma, kMaterials);                        \
  if (dir.empty()) {                                                                           \
    GTEST_SKIP() << "real materials unavailable: " CBRDF_SHARED_DIR                            \
                    "/data/nbrdf-merl or tools/make-merl.sh missing (or make-merl.sh failed)"; \
  }

class NoiseReal : public ::testing::TestWithParam<const char*> {};

TEST_P(NoiseReal, EstimateWithinAQuarterOfTheInjectedNoise) {
  const std::string sigma_text = GetParam();
  const double sigma = std::atof(sigma_text.c_str());
  CBRDF_NOISY_DIR_OR_SKIP(dir, sigma_text);
  for (const std::string& name : kMaterials) {
    SCOPED_TRACE(name);
    auto clean = read_merl(dir / (name + ".binary"));
    auto noisy = read_merl(dir / (name + "-noisy.binary"));
    ASSERT_TRUE(clean.ok()) << clean.status().message();
    ASSERT_TRUE(noisy.ok()) << noisy.status().message();
    const NoiseEstimate ce = estimate_noise(*clean, {.ceiling = false});
    EXPECT_FALSE(ce.noisy());
    for (double s : ce.sigma) EXPECT_LT(s, 0.1 * sigma);
    const NoiseEstimate ne = estimate_noise(*noisy);
    EXPECT_TRUE(ne.noisy());
    for (double s : ne.sigma) EXPECT_NEAR(s, sigma, 0.25 * sigma);
    for (const auto& b : ne.band_sigma) {
      for (double s : b) EXPECT_NEAR(s, sigma, 0.25 * sigma);
    }
    // make-merl.sh's noise does not grow with the angle.
    EXPECT_NEAR(ne.grazing_growth, 1.0, 0.25);
    // The ceiling is what the noisy table itself scores against the truth.
    const ImageMetrics real = sphere_psnr(*clean, *noisy);
    EXPECT_NEAR(ne.psnr_ceiling_tonemapped, real.psnr_tonemapped, 1.5);
  }
}

INSTANTIATE_TEST_SUITE_P(Sigmas, NoiseReal, ::testing::Values("0.01", "0.03", "0.05"));

TEST(NoiseCli, InfoPrintsTheEstimate) {
  CBRDF_NOISY_DIR_OR_SKIP(dir, "0.03");
  const std::string noisy = (dir / "beige-fabric-noisy.binary").string();
  testing::CommandResult r = testing::run_cli("info '" + noisy + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::smatch m;
  ASSERT_TRUE(
      std::regex_search(r.out, m, std::regex("noise: ([0-9.]+)% / ([0-9.]+)% / ([0-9.]+)%")))
      << r.out;
  for (int c = 1; c <= 3; ++c) EXPECT_NEAR(std::stod(m[c].str()), 3.0, 0.75) << r.out;
  EXPECT_NE(r.out.find("noise floor: sphere PSNR"), std::string::npos) << r.out;
  r = testing::run_cli("info '" + (dir / "beige-fabric.binary").string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("noise: none measurable"), std::string::npos) << r.out;
  r = testing::run_cli("info --json '" + noisy + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\"psnr_ceiling_tonemapped\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"noisy\": true"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace cbrdf
