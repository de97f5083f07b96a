// SPDX-License-Identifier: MIT
// Fitting and reconstruction on synthetic tables, including the hard inputs.
#include "cbrdf/fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>

#include "cbrdf/coords.h"
#include "cbrdf/model.h"
#include "copula/copula.h"
#include "density/frank_grid.h"
#include "fit/marginals.h"
#include "table_builder.h"

namespace cbrdf {
namespace {

using testing::make_table;

// Largest relative error over measured bins.
double max_rel_error(const BrdfTable& ref, const BrdfTable& test) {
  double worst = 0;
  for (int c = 0; c < kChannels; ++c)
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (!ref.measured(c, i)) continue;
      const double r = ref.physical(c, i), t = test.physical(c, i);
      worst = std::max(worst, std::abs(t - r) / std::max(std::abs(r), 1e-300));
    }
  return worst;
}

void expect_clean_reconstruction(const BrdfTable& source, const BrdfTable& rec) {
  std::size_t bad = 0, mask_changed = 0;
  for (int c = 0; c < kChannels; ++c)
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      const double s = source.stored(c, i), r = rec.stored(c, i);
      if (s < 0) {
        mask_changed += std::memcmp(&s, &r, sizeof s) != 0;
      } else {
        bad += !(std::isfinite(r) && r >= 0);
      }
    }
  EXPECT_EQ(bad, 0u) << "negative, NaN or Inf values at measured bins";
  EXPECT_EQ(mask_changed, 0u) << "not-measured bins not preserved bit for bit";
}

TEST(Fit, ConstantTableIsReproducedOnlyWithImputedMarginals) {
  const BrdfTable t = make_table([](int c, int, int, int) { return 0.2 + 0.1 * c; });
  FitSettings st;
  auto imputed = fit_model(t, st);
  ASSERT_TRUE(imputed.ok()) << imputed.status().message();
  const BrdfTable rec = imputed->table();
  expect_clean_reconstruction(t, rec);
  EXPECT_LT(max_rel_error(t, rec), 1e-6);
  // The paper's naive marginals count missing bins as 0 and so skew every marginal near grazing.
  st.impute_missing = false;
  auto naive = fit_model(t, st);
  ASSERT_TRUE(naive.ok());
  EXPECT_GT(max_rel_error(t, naive->table()), 0.2);
}

TEST(Fit, RecoversAKnownFrankParameterAndMarginals) {
  // A table that is exactly a Frank copula model with chosen marginals, fully measured.
  std::vector<double> f1(90), f2(15), f3(180);
  for (int i = 0; i < 90; ++i) f1[i] = std::exp(-0.08 * i) + 0.01;
  for (int j = 0; j < 15; ++j) f2[j] = 1.0 + 0.05 * j;
  for (int k = 0; k < 180; ++k) f3[k] = 1.0 + 0.3 * std::cos(k * std::numbers::pi / 180);
  for (auto* f : {&f1, &f2, &f3}) {
    double s = 0;
    for (double v : *f) s += v;
    for (double& v : *f) v /= s;
  }
  std::vector<double> u1, u2, u3;
  internal::midpoint_cdf(f1, &u1);
  internal::midpoint_cdf(f2, &u2);
  internal::midpoint_cdf(f3, &u3);
  const double alpha_true = -4.0, k_true = 5000.0;
  internal::FrankGrid g;
  g.prepare(alpha_true, u1, u2, u3);
  const BrdfTable t = make_table(
      [&](int c, int i, int j, int k) {
        return (1 + 0.1 * c) * k_true * g.density(i, j % 15, k) * f1[i] * f2[j % 15] * f3[k];
      },
      /*horizon_mask=*/false);
  FitReport report;
  auto m = fit_model(t, FitSettings{}, &report);
  ASSERT_TRUE(m.ok());
  // On a grid the model's own marginals (sums of c f1 f2 f3 over the other axes) differ slightly
  // from f1, f2, f3, since the sum only approximates the copula's integral: the empirical
  // marginals, and so the fit, are close to the truth but not exact.
  for (const Slice& s : m->slices) {
    for (int c = 0; c < kChannels; ++c) {
      EXPECT_NEAR(s.channel[c].theta, alpha_true, 0.02);
      EXPECT_NEAR(s.channel[c].scale / ((1 + 0.1 * c) * k_true), 1.0, 1e-3);
      for (int i = 0; i < 90; ++i) EXPECT_NEAR(s.channel[c].pdf_h[i], f1[i], 0.01 * f1[i]);
    }
  }
  EXPECT_LT(max_rel_error(t, m->table()), 0.05);
  // The separable model cannot express this table.
  EXPECT_GT(report.slices[0][0].objective_independence,
            100 * report.slices[0][0].objective + 1e-12);
}

TEST(Fit, AutoFamilyPicksTheFamilyThatMadeTheData) {
  // A fully measured table that is exactly a Clayton model (theta = 2) over chosen marginals.
  std::vector<double> f1(90), f2(90), f3(180);
  for (int i = 0; i < 90; ++i) f1[i] = 1.0 / 90;
  for (int j = 0; j < 90; ++j) f2[j] = 1.0 + 0.02 * j;
  for (int k = 0; k < 180; ++k) f3[k] = 1.0 + 0.5 * std::sin(k * std::numbers::pi / 180);
  for (auto* f : {&f2, &f3}) {
    double s = 0;
    for (double v : *f) s += v;
    for (double& v : *f) v /= s;
  }
  std::vector<double> u1, u3;
  internal::midpoint_cdf(f1, &u1);
  internal::midpoint_cdf(f3, &u3);
  const Copula& clayton = copula_for(CopulaFamily::kClayton);
  // One slice spanning all of theta_d: its CDF is over the 90 bins.
  std::vector<double> u2;
  internal::midpoint_cdf(f2, &u2);
  const BrdfTable t = make_table(
      [&](int c, int i, int j, int k) {
        // Only the red channel carries data (the others are all zero and skip the fit), which
        // keeps this four-family fit of 1.4 million bins quick.
        return c == 0 ? 1e4 * clayton.density(u1[i], u2[j], u3[k], 2.0) * f1[i] * f2[j] * f3[k]
                      : 0.0;
      },
      /*horizon_mask=*/false);
  FitSettings st;
  st.slices = 1;
  st.auto_family = true;
  st.threads = 2;
  FitReport report;
  auto m = fit_model(t, st, &report);
  ASSERT_TRUE(m.ok());
  EXPECT_EQ(m->slices[0].channel[0].family, CopulaFamily::kClayton);
  // Biased low: Clayton's density peaks at the corner u = 0, where the midpoint-grid sums that
  // give the empirical marginals stray furthest from the copula's integrals (1.66 measured).
  EXPECT_NEAR(m->slices[0].channel[0].theta, 2.0, 0.5);
  EXPECT_EQ(m->slices[0].channel[1].scale, 0.0);  // an all-zero channel
  // And Frank, fitted alone, does worse on it.
  st.auto_family = false;
  FitReport frank_report;
  ASSERT_TRUE(fit_model(t, st, &frank_report).ok());
  EXPECT_LT(report.slices[0][0].objective, frank_report.slices[0][0].objective);
}

TEST(Fit, CopulaFitIsNeverWorseThanSeparable) {
  const BrdfTable t = make_table([](int c, int i, int j, int k) {
    const double th = theta_h_of(i), td = theta_d_of(j);
    return (0.05 + 0.02 * c) + 3.0 * std::exp(-th * th / (0.01 + 0.02 * std::cos(td))) *
                                   (1.0 + 0.2 * std::cos(k * std::numbers::pi / 90));
  });
  FitReport report;
  auto m = fit_model(t, FitSettings{}, &report);
  ASSERT_TRUE(m.ok());
  for (const auto& s : report.slices)
    for (const auto& c : s) EXPECT_LE(c.objective, c.objective_independence * (1 + 1e-12));
  expect_clean_reconstruction(t, m->table());
}

TEST(Fit, AllZeroChannelAndEmptySlice) {
  BrdfTable t = make_table([](int c, int i, int, int) { return c == 1 ? 0.0 : 0.5 + 0.01 * i; });
  // Theta_d bins 30 to 44 (slice 2 of 6) not measured at all, with a distinctive stored value.
  for (std::size_t idx = 0; idx < kBinsPerChannel; ++idx) {
    const BinIndex b = merl_bin(idx);
    if (b.theta_d >= 30 && b.theta_d < 45) t.set_not_measured(idx, -2.5);
  }
  auto m = fit_model(t, FitSettings{});
  ASSERT_TRUE(m.ok());
  EXPECT_EQ(m->slices[2].channel[0].scale, 0.0);
  EXPECT_EQ(m->not_measured.values.size(), m->not_measured.count());  // mixed values: kept per bin
  const BrdfTable rec = m->table();
  expect_clean_reconstruction(t, rec);
  for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
    if (t.measured(1, i)) {
      ASSERT_EQ(rec.stored(1, i), 0.0) << i;
    }
  }
  EXPECT_LT(max_rel_error(t, rec), 1e-3);
}

TEST(Fit, DenormalScaleAndSingleNonZeroBin) {
  const BrdfTable tiny =
      make_table([](int c, int i, int, int) { return 1e-310 * (1 + c) * (1 + 0.01 * i); });
  // Below the supported value range (fit.h, kMinPeakMeasuredValue): refused, not decoded from a
  // subnormal K that carries few significant digits.
  auto m = fit_model(tiny, FitSettings{});
  ASSERT_FALSE(m.ok());
  EXPECT_EQ(m.status().code(), ErrorCode::kNumeric);

  BrdfTable one = make_table([](int, int, int, int) { return 0.0; });
  const std::size_t hot = merl_index(3, 20, 40);
  for (int c = 0; c < kChannels; ++c) one.set_physical(c, hot, 7.0 + c);
  auto m1 = fit_model(one, FitSettings{});
  ASSERT_TRUE(m1.ok());
  const BrdfTable rec1 = m1->table();
  expect_clean_reconstruction(one, rec1);
  for (int c = 0; c < kChannels; ++c) EXPECT_NEAR(rec1.physical(c, hot), 7.0 + c, 1e-9);
}

TEST(Fit, NearMirrorStaysFinite) {
  // Mass concentrated in the first two theta_h bins: an extremely skewed marginal.
  const BrdfTable t = make_table(
      [](int c, int i, int j, int) { return (i < 2 ? 1e4 * (1 + c) : 1e-6) * (1.0 + 0.01 * j); });
  FitReport report;
  auto m = fit_model(t, FitSettings{}, &report);
  ASSERT_TRUE(m.ok());
  const BrdfTable rec = m->table();
  expect_clean_reconstruction(t, rec);
  EXPECT_LT(max_rel_error(t, rec), 1e-2);
}

TEST(Fit, DeterministicAcrossThreadCounts) {
  const BrdfTable t = make_table([](int c, int i, int j, int k) {
    return 0.1 + c * 0.01 + std::exp(-0.1 * i) * (1 + 0.01 * j) * (1 + 0.1 * std::sin(0.03 * k));
  });
  FitSettings one, two;
  two.threads = 2;
  auto a = fit_model(t, one), b = fit_model(t, two);
  ASSERT_TRUE(a.ok() && b.ok());
  for (std::size_t s = 0; s < a->slices.size(); ++s)
    for (int c = 0; c < kChannels; ++c) {
      EXPECT_EQ(a->slices[s].channel[c].theta, b->slices[s].channel[c].theta);
      EXPECT_EQ(a->slices[s].channel[c].pdf_h, b->slices[s].channel[c].pdf_h);
    }
}

TEST(Fit, SettingsAreValidated) {
  const BrdfTable t;
  FitSettings st;
  st.slices = 0;
  EXPECT_EQ(fit_model(t, st).status().code(), ErrorCode::kInvalidArgument);
  st.slices = 91;
  EXPECT_NE(fit_model(t, st).status().message().find("outside 1 to 90"), std::string::npos);
  st.slices = 6;
  st.slice_bounds = {0, 30, 30, 90};
  EXPECT_EQ(fit_model(t, st).status().code(), ErrorCode::kInvalidArgument);
  st.slice_bounds = {0, 45, 90};
  auto b = slice_bounds(st);
  ASSERT_TRUE(b.ok());
  EXPECT_EQ(*b, (std::vector<int>{0, 45, 90}));
  st.slice_bounds.clear();
  st.slices = 90;
  EXPECT_EQ(slice_bounds(st)->size(), 91u);
}

TEST(ModelEvaluator, EvalEqualsTableAtBinsIsReciprocalAndZeroBelowHorizon) {
  const BrdfTable t = make_table([](int c, int i, int j, int k) {
    return 0.1 + c * 0.01 + std::exp(-0.1 * i) * (1 + 0.01 * j) * (1 + 0.1 * std::sin(0.03 * k));
  });
  auto m = fit_model(t, FitSettings{});
  ASSERT_TRUE(m.ok());
  const ModelEvaluator ev(*m);
  const BrdfTable rec = ev.table();
  for (int i : {1, 10, 40, 70}) {
    for (int j : {5, 14, 15, 44, 60}) {
      for (int k : {0, 33, 90, 179}) {
        if (bin_below_horizon(i, j, k)) continue;
        Vec3 wi, wo;
        from_half_diff(HalfDiff{theta_h_of(i), 0.7, theta_d_of(j), phi_d_of(k)}, &wi, &wo);
        if (wi.z <= 0 || wo.z <= 0) continue;
        double a[3], b[3];
        ev.eval(wi, wo, a);
        ev.eval(wo, wi, b);
        const std::size_t idx = merl_index(i, j, k);
        for (int c = 0; c < kChannels; ++c) {
          EXPECT_NEAR(a[c], rec.physical(c, idx), 1e-6 * rec.physical(c, idx)) << i << j << k;
          EXPECT_NEAR(a[c], b[c], 1e-6 * a[c]);
        }
      }
    }
  }
  double rgb[3];
  ev.eval({0, 0, 1}, {0.6, 0, -0.8}, rgb);
  EXPECT_EQ(rgb[0] + rgb[1] + rgb[2], 0.0);
  // Continuous across a slice boundary (theta_d bin 15) and across phi_d = 180 -> 0.
  auto at = [&](double h, double d, double p) {
    Vec3 wi, wo;
    from_half_diff(HalfDiff{theta_h_of(h), 0.0, theta_d_of(d), phi_d_of(p)}, &wi, &wo);
    double v[3];
    ev.eval(wi, wo, v);
    return v[0];
  };
  EXPECT_NEAR(at(20.3, 14.9999, 50.5), at(20.3, 15.0001, 50.5), 1e-4 * at(20.3, 15, 50.5));
  EXPECT_NEAR(at(20.3, 10.5, 179.9999), at(20.3, 10.5, 0.0001), 1e-4 * at(20.3, 10.5, 0.0));
}

}  // namespace
}  // namespace cbrdf
