// SPDX-License-Identifier: MIT
// fit_analytic recovers the parameters of tables made from known analytic BRDFs.
#include "cbrdf/analytic_fit.h"

#include <gtest/gtest.h>

#include <cmath>

#include "cbrdf/samples.h"
#include "metrics.h"

namespace cbrdf {
namespace {

void expect_near_rel(double want, double got, double rel, const std::string& what) {
  EXPECT_NEAR(got, want, rel * std::abs(want) + 1e-9) << what;
}

void expect_recovers(const AnalyticBrdf& truth, AnalyticLoss loss, double rel) {
  auto table = tabulate(truth);
  ASSERT_TRUE(table.ok()) << table.status().message();
  AnalyticFitSettings st;
  st.lobes.clear();
  for (const Lobe& l : truth.lobes) st.lobes.push_back(l.kind);
  st.sample_bins = 5000;
  st.loss = loss;
  st.threads = 2;
  AnalyticFitReport report;
  auto fit = fit_analytic(*table, st, &report);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  EXPECT_EQ(report.bins, 5000);
  EXPECT_LE(report.final_cost, report.start_cost);
  EXPECT_LT(report.final_cost, 1e-12);
  ASSERT_EQ(fit->lobes.size(), truth.lobes.size());
  for (std::size_t l = 0; l < truth.lobes.size(); ++l) {
    const Lobe& want = truth.lobes[l];
    const Lobe& got = fit->lobes[l];
    const std::string name = std::string(lobe_kind_name(want.kind)) + " lobe " + std::to_string(l);
    EXPECT_EQ(got.kind, want.kind);
    for (int c = 0; c < 3; ++c) expect_near_rel(want.rgb[c], got.rgb[c], rel, name + " colour");
    if (want.kind != LobeKind::kLambertian)
      expect_near_rel(want.shape, got.shape, rel, name + " shape");
  }
}

TEST(AnalyticFit, RecoversLambertianPlusWard) {
  expect_recovers(AnalyticBrdf{{lambertian({0.05, 0.10, 0.30}), ward({0.20, 0.25, 0.35}, 0.2)}},
                  AnalyticLoss::kCosineWeighted, 1e-4);
}

TEST(AnalyticFit, RecoversLambertianPlusGgx) {
  expect_recovers(AnalyticBrdf{{lambertian({0.55, 0.08, 0.06}), ggx({0.04, 0.05, 0.06}, 0.12)}},
                  AnalyticLoss::kCosineWeighted, 1e-4);
}

TEST(AnalyticFit, RecoversAshikhminShirleyWithTheLogLoss) {
  expect_recovers(
      AnalyticBrdf{{lambertian({0.10, 0.35, 0.12}), ashikhmin_shirley({0.05, 0.06, 0.07}, 300.0)}},
      AnalyticLoss::kLog, 1e-4);
}

TEST(AnalyticFit, RecoversTwoGgxLobes) {
  expect_recovers(AnalyticBrdf{{lambertian({0.2, 0.2, 0.1}), ggx({0.5, 0.4, 0.3}, 0.05),
                                ggx({0.1, 0.15, 0.2}, 0.4)}},
                  AnalyticLoss::kCosineWeighted, 1e-3);
}

TEST(AnalyticFit, WrongModelFitsWorseThanTheRightOne) {
  auto table = make_sample("plastic");  // Lambertian + GGX 0.12
  ASSERT_TRUE(table.ok());
  AnalyticFitSettings st;
  st.sample_bins = 4000;
  st.lobes = {LobeKind::kLambertian, LobeKind::kGgx};
  AnalyticFitReport right, wrong;
  ASSERT_TRUE(fit_analytic(*table, st, &right).ok());
  st.lobes = {LobeKind::kLambertian};
  ASSERT_TRUE(fit_analytic(*table, st, &wrong).ok());
  EXPECT_GT(wrong.final_cost, 1e6 * right.final_cost);
}

TEST(AnalyticFit, SameSeedSameResultOtherSeedOtherBins) {
  auto table = make_sample("ward");
  ASSERT_TRUE(table.ok());
  // Fit the wrong lobe so that the result depends on which bins were drawn.
  AnalyticFitSettings st;
  st.sample_bins = 2000;
  st.lobes = {LobeKind::kLambertian, LobeKind::kAshikhminShirley};
  auto a = fit_analytic(*table, st);
  auto b = fit_analytic(*table, st);
  st.seed = 7;
  auto c = fit_analytic(*table, st);
  ASSERT_TRUE(a.ok() && b.ok() && c.ok());
  EXPECT_EQ(a->lobes[1].shape, b->lobes[1].shape);
  EXPECT_EQ(a->lobes[0].rgb, b->lobes[0].rgb);
  EXPECT_NE(a->lobes[1].shape, c->lobes[1].shape);
}

TEST(AnalyticFit, RejectsBadSettings) {
  const BrdfTable table;
  AnalyticFitSettings st;
  st.lobes.clear();
  EXPECT_EQ(fit_analytic(table, st).status().code(), ErrorCode::kInvalidArgument);
  st.lobes.assign(5, LobeKind::kLambertian);
  EXPECT_EQ(fit_analytic(table, st).status().code(), ErrorCode::kInvalidArgument);
  st.lobes = {LobeKind::kLambertian};
  st.max_angle_deg = 0;
  EXPECT_EQ(fit_analytic(table, st).status().code(), ErrorCode::kInvalidArgument);
  st.max_angle_deg = 80;
  st.sample_bins = -1;
  EXPECT_EQ(fit_analytic(table, st).status().code(), ErrorCode::kInvalidArgument);
  st.sample_bins = 10;
  st.threads = 0;
  EXPECT_EQ(fit_analytic(table, st).status().code(), ErrorCode::kInvalidArgument);
}

TEST(AnalyticFit, NothingMeasuredIsAnError) {
  BrdfTable table;
  for (std::size_t i = 0; i < kBinsPerChannel; ++i) table.set_not_measured(i);
  auto fit = fit_analytic(table, AnalyticFitSettings{});
  ASSERT_FALSE(fit.ok());
  EXPECT_EQ(fit.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(fit.status().message().find("no bin is measured"), std::string::npos);
}

TEST(TabulateLike, KeepsTheReferenceMaskAndMatchesTabulate) {
  const AnalyticBrdf brdf{{lambertian({0.3, 0.2, 0.1}), ggx({0.05, 0.05, 0.05}, 0.3)}};
  auto full = tabulate(brdf);
  ASSERT_TRUE(full.ok());
  BrdfTable reference = *full;
  reference.set_stored(1, merl_index(10, 20, 30), -3.5);  // a channel-specific unusual value
  auto like = tabulate_like(brdf, reference);
  ASSERT_TRUE(like.ok());
  for (int c = 0; c < 3; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (reference.measured(c, i)) {
        ASSERT_EQ(like->stored(c, i), full->stored(c, i));
      } else {
        ASSERT_EQ(like->stored(c, i), reference.stored(c, i));
      }
    }
  }
  EXPECT_EQ(like->stored(1, merl_index(10, 20, 30)), -3.5);
  EXPECT_EQ(brdf_metrics(reference, *like).rel_rmse_mean, 0.0);
}

TEST(TabulateLike, RejectsAnInvalidBrdf) {
  const AnalyticBrdf bad{{ggx({0.1, 0.1, 0.1}, -1.0)}};
  EXPECT_FALSE(tabulate_like(bad, BrdfTable{}).ok());
}

}  // namespace
}  // namespace cbrdf
