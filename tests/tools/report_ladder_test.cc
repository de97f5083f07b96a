// SPDX-License-Identifier: MIT
// The report's ladder (report/ladder*.h): curve reading and the checks on hand-made points,
// the ZFP baseline's bound, and one cheap ladder measured on a synthetic material.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "cbrdf/codec.h"
#include "cbrdf/encoder.h"
#include "cbrdf/encoder_options.h"
#include "report/ladder.h"
#include "report/ladder_check.h"
#include "report/ladder_output.h"
#include "report/zfp_baseline.h"
#include "table_builder.h"
#include "test_support.h"

namespace cbrdf::report {
namespace {

LadderPoint point(const char* method, double bytes, double psnr) {
  LadderPoint p{method, std::to_string(int(psnr)) + " dB"};
  p.bytes = bytes;
  p.psnr_tonemapped = psnr;
  p.psnr_linear = psnr - 10;
  return p;
}

TEST(LadderCurve, KeepsTheLowerEnvelopeAndInterpolatesInLogBytes) {
  LadderMaterial m{"m", std::vector<LadderPoint>{
                            point(kLadderBase, 2000, 40), point(kLadderBase, 5000, 38),  // beaten
                            point(kLadderResidual, 20000, 60), point(kLadderResidual, 200000, 80),
                            point(kLadderZfp, 1000, 90)}};
  const std::vector<CurvePoint> c = ladder_curve(m, cbrdf_methods());
  ASSERT_EQ(c.size(), 3u);
  EXPECT_EQ(c[0].bytes, 2000);
  EXPECT_EQ(c[1].bytes, 20000);
  EXPECT_EQ(c[2].bytes, 200000);
  // Halfway in PSNR between 20 KB and 200 KB: the geometric mean.
  EXPECT_NEAR(bytes_at(c, 70), std::sqrt(20000.0 * 200000.0), 1e-6);
  EXPECT_NEAR(bytes_at(c, 50), std::sqrt(2000.0 * 20000.0), 1e-6);
  EXPECT_EQ(bytes_at(c, 30), 2000);  // below the curve: its fewest bytes
  EXPECT_TRUE(std::isnan(bytes_at(c, 81)));
  EXPECT_TRUE(std::isnan(bytes_at({}, 50)));
}

// cbrdf 10x fewer bytes than ZFP everywhere, float16 one point at 90 dB; lossless beats xz on
// one of two materials.
std::vector<LadderMaterial> hand_made() {
  std::vector<LadderMaterial> out;
  for (int i = 0; i < 2; ++i) {
    LadderMaterial m;
    m.name = "m" + std::to_string(i);
    m.points = {point(kLadderBase, 4000, 40), point(kLadderResidual, 40000, 85),
                point(kLadderZfp, 40000, 40), point(kLadderZfp, 400000, 85),
                point(kLadderFloat16, 1e6, 90)};
    LadderPoint lossless = point(kLadderLossless, i == 0 ? 8e6 : 25e6, 100);
    LadderPoint xz = point(kLadderXz, 20e6, 100);
    m.points.push_back(lossless);
    m.points.push_back(xz);
    out.push_back(m);
  }
  return out;
}

TEST(LadderCheck, RatiosAtEachTargetAnd60DbAndLossless) {
  const std::vector<LadderTarget> t = ladder_targets(hand_made());
  ASSERT_EQ(t.size(), 8u);  // 45, 50, ..., 80
  for (const LadderTarget& x : t) {
    EXPECT_EQ(x.materials, 2);
    EXPECT_NEAR(x.zfp_bytes / x.cbrdf_bytes, 10.0, 1e-9) << x.psnr;
    EXPECT_NEAR(x.zfp_ratio_min, 10.0, 1e-9);
    EXPECT_NEAR(x.float16_bytes, 1e6, 1e-6);
  }
  EXPECT_NEAR(t[0].cbrdf_bytes, 4000 * std::pow(10.0, 5.0 / 45), 1e-6);
  const std::string text = ladder_check_text(hand_made());
  EXPECT_TRUE(testing::contains(text, "45 dB: cbrdf")) << text;
  EXPECT_TRUE(testing::contains(text, "ZFP/cbrdf 10.00 (min 10.00) ok")) << text;
  EXPECT_TRUE(testing::contains(text, "smaller than xz on 1 of 2 materials")) << text;
  EXPECT_TRUE(testing::contains(text, "NOT ALL")) << text;
  EXPECT_TRUE(testing::contains(text, "60 dB: cbrdf mean")) << text;
  const std::vector<LosslessCheck> lc = lossless_checks(hand_made());
  ASSERT_EQ(lc.size(), 2u);
  EXPECT_EQ(lc[0].cbrdf, 8e6);
  EXPECT_EQ(lc[0].xz, 20e6);
}

TEST(LadderCheck, ZfpShortOfATargetCountsItsLargestFileAsALowerBound) {
  LadderMaterial m;
  m.name = "dark";
  m.points = {point(kLadderResidual, 10000, 45), point(kLadderResidual, 100000, 85),
              point(kLadderZfp, 50000, 40), point(kLadderZfp, 500000, 60)};
  const std::vector<LadderTarget> t = ladder_targets({m});
  ASSERT_EQ(t.size(), 8u);
  EXPECT_EQ(t[3].psnr, 60);
  EXPECT_EQ(t[3].zfp_short, 0);
  EXPECT_NEAR(t[3].zfp_bytes, 500000, 1e-6);
  EXPECT_EQ(t[4].zfp_short, 1);  // 65 dB: ZFP stops at 60
  EXPECT_EQ(t[4].materials, 1);
  EXPECT_NEAR(t[4].zfp_bytes, 500000, 1e-6);
  EXPECT_TRUE(testing::contains(ladder_check_text({m}), "ZFP short of it on 1"))
      << ladder_check_text({m});
}

TEST(LadderOutput, TablesFiguresAndFilesHoldEveryPoint) {
  const std::vector<LadderMaterial> l = hand_made();
  const std::vector<TextTable> tables = ladder_tables(l);
  ASSERT_EQ(tables.size(), 3u);
  EXPECT_EQ(tables[0].rows.size(), 8u);  // targets
  EXPECT_EQ(tables[1].rows.size(), 7u);  // method x setting
  EXPECT_EQ(tables[2].rows.size(), 2u);  // lossless per material
  const std::vector<Figure> figures = ladder_figures(l);
  ASSERT_EQ(figures.size(), 3u);  // the mean and one per material
  EXPECT_EQ(figures[0].file, "ladder_mean.svg");
  EXPECT_TRUE(testing::contains(figures[0].svg, "<svg"));
  EXPECT_TRUE(testing::contains(figures[0].svg, kLadderZfp));
  const std::string csv = ladder_csv(l);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 2 * 7);
  EXPECT_TRUE(testing::contains(ladder_json(l), "\"zfp_ratio_min\""));
  EXPECT_TRUE(ladder_tables({}).empty());
}

BrdfTable smooth_material() {
  return testing::make_table([](int c, int h, int d, int p) {
    const double th = h / 90.0, td = d / 90.0;
    return 0.05 * (c + 1) + 3.0 * std::exp(-40 * th * th) * (1 + 0.3 * td) + 0.001 * p / 180.0;
  });
}

TEST(ZfpBaseline, MeetsItsToleranceAndKeepsTheMask) {
  const BrdfTable t = smooth_material();
  auto z = zfp_log_round_trip(t, 0.01);
  ASSERT_TRUE(z.ok()) << z.status().message();
  double worst = 0;
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      ASSERT_EQ(t.measured(c, i), z->decoded.measured(c, i)) << i;
      if (!t.measured(c, i)) continue;
      worst = std::max(
          worst, std::abs(std::log1p(z->decoded.physical(c, i)) - std::log1p(t.physical(c, i))));
    }
  }
  EXPECT_LE(worst, 0.01);
  EXPECT_GT(worst, 0.0);
  auto finer = zfp_log_round_trip(t, 0.0001);
  ASSERT_TRUE(finer.ok());
  EXPECT_GT(finer->compressed.bytes.size(), z->compressed.bytes.size());
  EXPECT_FALSE(zfp_log_round_trip(t, 0).ok());
}

TEST(Ladder, MeasuresEveryMethodOnASmallSetting) {
  LadderSettings st;
  st.base_components = {1};
  st.base_bits = {8};
  // Finer than the real materials' 0.01: the 8-bit base already reads 61 dB on this smooth
  // material, and mode 3's finest level (8 E) in the coarsest rows (64 E) would not beat it.
  st.max_errors = {0.002};
  st.zfp_tolerances = {0.01};
  st.zstd_level = 1;
  st.compressors = false;  // xz alone would take seconds; lossless.h has its own tests
  st.sphere_size = 48;
  auto l = measure_ladder("smooth", smooth_material(), st);
  ASSERT_TRUE(l.ok()) << l.status().message();
  const char* const want[] = {kLadderBase, kLadderResidual, kLadderLossless, kLadderZfp,
                              kLadderFloat16};
  ASSERT_EQ(l->points.size(), std::size(want));
  for (std::size_t i = 0; i < std::size(want); ++i) {
    const LadderPoint& p = l->points[i];
    EXPECT_EQ(p.method, want[i]);
    EXPECT_GT(p.bytes, 0) << p.method;
    EXPECT_GE(p.encode_s, 0) << p.method;
    EXPECT_TRUE(std::isfinite(p.psnr_tonemapped)) << p.method;
  }
  const LadderPoint& base = l->points[0];
  const LadderPoint& residual = l->points[1];
  EXPECT_GT(residual.psnr_tonemapped, base.psnr_tonemapped);
  EXPECT_GT(residual.bytes, base.bytes);
  EXPECT_TRUE(l->points[2].exact);
  EXPECT_FALSE(l->points[3].exact);
  // Smooth data: the exact coding takes far fewer than the .binary's 35 MB.
  EXPECT_LT(l->points[2].bytes, 8e6);
  // The residual point reuses the base points' fit, and is the very file a whole encode with the
  // rate control's residual (row steps, interpolated levels, per-level step multipliers) writes.
  EncoderOptions o;
  o.components = "1";
  o.bits = std::to_string(st.residual_base_bits);
  o.source_name = "smooth";
  o.max_error = 0.002;
  auto es = encoder_settings(o);
  ASSERT_TRUE(es.ok());
  es->residual = target_residual_settings(0.002);
  auto whole = encode_table(smooth_material(), *es);
  ASSERT_TRUE(whole.ok()) << whole.status().message();
  EXPECT_EQ(double(whole->bytes.size()), residual.bytes);
  auto info = inspect_container(whole->bytes);
  ASSERT_TRUE(info.ok());
  EXPECT_EQ(info->residual_mode, 4);  // RESD mode 4: the per-level multipliers of container 1.3
}

}  // namespace
}  // namespace cbrdf::report
