// SPDX-License-Identifier: MIT
// `cbrdf report --ladder --truth DIR` on a noisy table (issue 30): every point measured against
// the truth beside the input, the noise floor's point and level on the ladder.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <random>

#include "cbrdf/merl_io.h"
#include "cbrdf/metrics.h"
#include "report/ladder.h"
#include "report/ladder_output.h"
#include "table_builder.h"
#include "test_support.h"

namespace cbrdf::report {
namespace {

// A smooth material with structure the one-component model misses (a tinted sheen at grazing
// theta_d), so that the residual has signal to code under the noise.
BrdfTable truth_material() {
  return testing::make_table([](int c, int h, int d, int p) {
    const double th = h / 90.0, td = d / 90.0, f = p / 180.0;
    return 0.05 * (c + 1) + 3.0 * std::exp(-40 * th * th) * (1 + 0.3 * td) +
           0.2 * td * td * td * (1 + std::cos(6.28 * f));
  });
}

LadderSettings small_ladder() {
  LadderSettings st;
  st.base_components = {1};
  st.base_bits = {8};
  st.max_errors = {0.01, 0.002};
  st.zfp_tolerances = {0.01};
  st.float16 = false;
  st.zstd_level = 1;
  st.compressors = false;
  st.sphere_size = 64;
  return st;
}

TEST(ReportNoise, LadderAgainstTheTruthMarksTheNoiseFloor) {
  const BrdfTable truth = truth_material();
  const BrdfTable noisy = testing::with_noise(truth, 0.03, 9);
  auto l = measure_ladder("noisy", noisy, small_ladder(), &truth);
  ASSERT_TRUE(l.ok()) << l.status().message();
  EXPECT_NEAR(l->noise_sigma, 0.03, 0.0075);
  EXPECT_GT(l->noise_ceiling_tonemapped, 20);
  EXPECT_LT(l->noise_ceiling_tonemapped, kPsnrCapDb);
  const LadderPoint* floor = nullptr;
  const LadderPoint* lossless = nullptr;
  const LadderPoint* finest = nullptr;
  for (const LadderPoint& p : l->points) {
    EXPECT_TRUE(std::isfinite(p.psnr_truth_tonemapped)) << p.method << " " << p.setting;
    if (p.method == kLadderNoiseFloor) floor = &p;
    if (p.method == kLadderLossless) lossless = &p;
    if (p.method == kLadderResidual && p.setting == "E 0.002") finest = &p;
  }
  ASSERT_TRUE(floor && lossless && finest);
  // The lossless file is the input: its PSNR against the truth is the input's own.
  SphereSetup s;
  s.size = 64;
  EXPECT_DOUBLE_EQ(lossless->psnr_truth_tonemapped, sphere_psnr(truth, noisy, s).psnr_tonemapped);
  // The noise floor's file is closer to the truth than the input and than a residual that codes
  // the noise, in fewer bytes than that one.
  EXPECT_GT(floor->psnr_truth_tonemapped, lossless->psnr_truth_tonemapped);
  EXPECT_GT(floor->psnr_truth_tonemapped, finest->psnr_truth_tonemapped);
  EXPECT_LT(floor->bytes, finest->bytes);

  const std::vector<LadderMaterial> ls = {*l};
  const std::vector<Figure> figures = ladder_figures(ls);
  ASSERT_FALSE(figures.empty());
  EXPECT_TRUE(testing::contains(figures[0].svg, "noise floor (input)"));
  EXPECT_TRUE(testing::contains(figures[0].svg, "vs truth"));
  const std::vector<TextTable> tables = ladder_tables(ls);
  ASSERT_EQ(tables.size(), 3u);
  EXPECT_EQ(tables[1].header.back(), "PSNR tm truth (dB)");
  EXPECT_TRUE(testing::contains(tables[1].note, "noise floor"));
  const std::string csv = ladder_csv(ls);
  EXPECT_TRUE(testing::contains(csv, ",psnr_truth_tonemapped\n"));
  EXPECT_TRUE(testing::contains(ladder_json(ls), "\"noise_ceiling_tonemapped\""));
}

// A smooth table has no noise-floor point and no truth column without --truth.
TEST(ReportNoise, SmoothTableWithoutTruth) {
  LadderSettings st = small_ladder();
  st.max_errors = {0.01};
  st.lossless = false;
  st.zfp_tolerances = {};
  auto l = measure_ladder("smooth", truth_material(), st);
  ASSERT_TRUE(l.ok()) << l.status().message();
  for (const LadderPoint& p : l->points) {
    EXPECT_NE(p.method, kLadderNoiseFloor);
    EXPECT_TRUE(std::isnan(p.psnr_truth_tonemapped));
  }
  EXPECT_EQ(l->noise_ceiling_tonemapped, kPsnrCapDb);
  const std::vector<TextTable> tables = ladder_tables({*l});
  EXPECT_NE(tables[1].header.back(), "PSNR tm truth (dB)");
}

TEST(ReportNoise, TruthNeedsTheLadder) {
  testing::TempDir tmp;
  const auto path = tmp / "t.binary";
  ASSERT_TRUE(write_merl(path, truth_material()).ok());
  const testing::CommandResult r =
      testing::run_cli("report '" + path.string() + "' --truth '" + tmp.path().string() + "' -o '" +
                       (tmp / "out").string() + "'");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_TRUE(testing::contains(r.err, "--truth")) << r.err;
}

// A ceiling that cannot be measured (NaN: noise.h) is written as cbrdf info --json writes it,
// not as JSON null.
TEST(ReportNoise, UnmeasurableCeilingIsSaidSoInTheJson) {
  LadderMaterial m;
  m.name = "wide";
  m.noise_ceiling_tonemapped = std::nan("");
  const nlohmann::json j = nlohmann::json::parse(ladder_json({m}));
  EXPECT_EQ(j["materials"][0]["noise_ceiling_tonemapped"], "not measurable");
  m.noise_ceiling_tonemapped = 41.5;
  EXPECT_EQ(nlohmann::json::parse(ladder_json({m}))["materials"][0]["noise_ceiling_tonemapped"],
            41.5);
}

}  // namespace
}  // namespace cbrdf::report
