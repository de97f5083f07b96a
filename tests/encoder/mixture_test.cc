// SPDX-License-Identifier: MIT
// Copula mixtures (several components per slice and channel): evaluation, fitting, coding.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>

#include "cbrdf/codec.h"
#include "cbrdf/container.h"
#include "cbrdf/coords.h"
#include "cbrdf/encoder.h"
#include "cbrdf/fit.h"
#include "cbrdf/model.h"
#include "cbrdf/samples.h"
#include "coding_1_2.h"
#include "synthetic_model.h"

namespace cbrdf {
namespace {

// Relative RMS error over measured bins, all channels.
double rel_rmse(const BrdfTable& ref, const BrdfTable& test) {
  double num = 0, den = 0;
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (!ref.measured(c, i)) continue;
      const double d = test.physical(c, i) - ref.physical(c, i);
      num += d * d;
      den += ref.physical(c, i) * ref.physical(c, i);
    }
  }
  return std::sqrt(num / den);
}

// Two separable lobes per slice channel (independence components): exactly a rank-2 mixture,
// which one product of marginals cannot express. Standard below-horizon mask.
Model two_lobe_model(const std::vector<int>& bounds) {
  Model m = testing::make_model(bounds, false, 21);
  for (Slice& s : m.slices) {
    for (int c = 0; c < kChannels; ++c) {
      ChannelSlice& cs = s.channel[std::size_t(c)];
      cs.family = CopulaFamily::kIndependence;
      cs.theta = 0;
      cs.pdf_h = testing::lobe_theta_h(0.6, 1e-3);
      cs.pdf_p = testing::smooth_phi_d(0.1);
      Component sharp;
      sharp.family = CopulaFamily::kIndependence;
      sharp.scale = cs.scale * (0.5 + 0.2 * c);
      sharp.pdf_h = testing::lobe_theta_h(0.05, 1e-6);
      sharp.pdf_d = testing::smooth_theta_d(s.theta_d_begin, s.theta_d_end, 0.9);
      sharp.pdf_p = testing::smooth_phi_d(0.9);
      cs.extra.push_back(sharp);
    }
  }
  return m;
}

TEST(Mixture, ValueIsTheSumOfItsComponents) {
  const Model mix = testing::make_mixture_model({0, 30, 90}, 4, 3);
  const ModelEvaluator ev(mix);
  const BrdfTable table = ev.table();
  // Each component alone, as a model of its own.
  std::vector<Model> parts;
  for (int r = 0; r < 4; ++r) {
    Model part = mix;
    for (Slice& s : part.slices) {
      for (ChannelSlice& cs : s.channel) {
        if (r < cs.components()) {
          const Component comp = cs.component(r);
          static_cast<Component&>(cs) = comp;
        } else {
          cs.scale = 0;
        }
        cs.extra.clear();
      }
    }
    parts.push_back(std::move(part));
  }
  std::vector<ModelEvaluator> part_ev;
  for (const Model& p : parts) part_ev.emplace_back(p);
  int checked = 0;
  for (std::size_t idx = 0; idx < kBinsPerChannel; idx += 997) {
    const BinIndex b = merl_bin(idx);
    for (int c = 0; c < kChannels; ++c) {
      double sum = 0;
      for (const ModelEvaluator& pe : part_ev)
        sum += pe.bin_value(c, b.theta_h, b.theta_d, b.phi_d);
      const double v = ev.bin_value(c, b.theta_h, b.theta_d, b.phi_d);
      EXPECT_NEAR(v, sum, 1e-12 * std::max(1.0, sum)) << idx;
      if (table.measured(c, idx)) {
        EXPECT_NEAR(table.physical(c, idx), v, 1e-12 * std::max(1.0, v)) << idx;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 1000);
  // Direction-pair evaluation is the same sum.
  const Vec3 wi = {0.3, 0.1, std::sqrt(1 - 0.1)}, wo = {-0.2, 0.25, std::sqrt(1 - 0.1025)};
  double rgb[3], sum_rgb[3] = {0, 0, 0};
  ev.eval(wi, wo, rgb);
  for (const ModelEvaluator& pe : part_ev) {
    double p[3];
    pe.eval(wi, wo, p);
    for (int c = 0; c < 3; ++c) sum_rgb[c] += p[c];
  }
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(rgb[c], sum_rgb[c], 1e-12 * std::max(1.0, sum_rgb[c]));
}

TEST(Mixture, RecoversATwoComponentTableThatOneComponentCannot) {
  const Model truth = two_lobe_model({0, 30, 60, 90});
  const BrdfTable table = truth.table();
  FitSettings st;
  st.slice_bounds = {0, 30, 60, 90};
  st.threads = 2;
  Expected<Model> one = fit_model(table, st);
  st.components = 2;
  FitReport report;
  Expected<Model> two = fit_model(table, st, &report);
  ASSERT_TRUE(one.ok() && two.ok());
  const double e1 = rel_rmse(table, one->table()), e2 = rel_rmse(table, two->table());
  std::printf("two-lobe table: rel RMSE %.3g with 1 component, %.3g with 2\n", e1, e2);
  // Not exact: HALS from the moment start stalls near 0.6% on this table (fit/mixture.h says why
  // the start is kept), 40 times below what one component can do.
  EXPECT_GT(e1, 0.1);
  EXPECT_LT(e2, 0.01);
  EXPECT_LT(e2 * 20, e1);
  for (const Slice& s : two->slices) {
    for (const ChannelSlice& cs : s.channel) EXPECT_EQ(cs.components(), 2);
  }
  for (const auto& s : report.slices) {
    for (const ChannelSliceFit& f : s) EXPECT_GT(f.hals_sweeps, 0);
  }
}

TEST(Mixture, NotMeasuredBinsAreImputedNotFittedAsZero) {
  // The same rank-2 table with and without a large not-measured region: the masked fit must
  // still predict the hidden bins (they are not zeros to fit).
  const Model truth = two_lobe_model({0, 90});
  BrdfTable full = truth.table();
  BrdfTable masked = full;
  std::size_t hidden = 0;
  for (std::size_t idx = 0; idx < kBinsPerChannel; ++idx) {
    const BinIndex b = merl_bin(idx);
    if (!full.measured(0, idx) || b.phi_d >= 30 || b.theta_d < 20) continue;
    masked.set_not_measured(idx);
    ++hidden;
  }
  ASSERT_GT(hidden, 100000u);
  FitSettings st;
  st.slices = 1;
  st.components = 2;
  st.threads = 2;
  Expected<Model> fit = fit_model(masked, st);
  ASSERT_TRUE(fit.ok());
  const ModelEvaluator ev(*fit);
  double num = 0, den = 0;
  for (std::size_t idx = 0; idx < kBinsPerChannel; ++idx) {
    if (masked.measured(0, idx) || !full.measured(0, idx)) continue;
    const BinIndex b = merl_bin(idx);
    const double d = ev.bin_value(0, b.theta_h, b.theta_d, b.phi_d) - full.physical(0, idx);
    num += d * d;
    den += full.physical(0, idx) * full.physical(0, idx);
  }
  const double hidden_err = std::sqrt(num / den);
  std::printf("hidden region: rel RMSE %.3g over %zu bins\n", hidden_err, hidden);
  // Fitted as zeros, the hidden bins would come out near 0 (error near 1); imputed, they follow the
  // measured part's components (2% measured here).
  EXPECT_LT(hidden_err, 0.05);
  // The reconstruction keeps the hidden bins' stored values bit for bit.
  const BrdfTable rec = fit->table();
  for (std::size_t idx = 0; idx < kBinsPerChannel; idx += 101) {
    const double a = masked.stored(0, idx), b = rec.stored(0, idx);
    if (a < 0) {
      EXPECT_EQ(std::memcmp(&a, &b, sizeof a), 0) << idx;
    }
  }
}

TEST(Mixture, MoreComponentsNeverFitWorse) {
  const BrdfTable table = make_sample("ggx-sharp").value();
  double prev = HUGE_VAL;
  for (int k = 1; k <= 3; ++k) {
    FitSettings st;
    st.slices = 2;
    st.components = k;
    st.threads = 2;
    FitReport report;
    ASSERT_TRUE(fit_model(table, st, &report).ok());
    double obj = 0;
    for (const auto& s : report.slices) {
      for (const ChannelSliceFit& f : s) obj += f.objective;
    }
    std::printf("ggx-sharp, 2 slices: objective %.6g with %d component(s)\n", obj, k);
    EXPECT_LE(obj, prev * (1 + 1e-9));
    if (k > 1) {
      EXPECT_LT(obj, 0.9 * prev) << "a second lobe of GGX is worth a lot";
    }
    prev = obj;
  }
}

TEST(Mixture, AutoComponentsStopWhenAComponentDoesNotPay) {
  FitSettings st;
  st.slice_bounds = {0, 45, 90};
  st.components = 3;  // auto, up to 3 (kAutoMaxComponents is 4; 3 keeps the test short)
  st.auto_components = true;
  st.threads = 2;
  // Rank 2 by construction: auto keeps 2 (a third cannot halve an error that is already ~0...
  // it can, relatively, so the test only pins that at least 2 are kept), and a separable table
  // keeps 1.
  Expected<Model> two = fit_model(two_lobe_model({0, 45, 90}).table(), st);
  ASSERT_TRUE(two.ok());
  for (const Slice& s : two->slices) {
    for (const ChannelSlice& cs : s.channel) EXPECT_GE(cs.components(), 2);
  }
  Model separable = two_lobe_model({0, 45, 90});
  for (Slice& s : separable.slices) {
    for (ChannelSlice& cs : s.channel) cs.extra.clear();
  }
  Expected<Model> one = fit_model(separable.table(), st);
  ASSERT_TRUE(one.ok());
  for (const Slice& s : one->slices) {
    for (const ChannelSlice& cs : s.channel) EXPECT_EQ(cs.components(), 1);
  }
}

TEST(Mixture, DeterministicAcrossThreadCountsAndHardInputsStayFinite) {
  BrdfTable table = make_sample("near-mirror").value();
  // Channel B all zero: no components at all beyond the zero first one.
  for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
    if (table.measured(2, i)) table.set_physical(2, i, 0.0);
  }
  FitSettings st;
  st.slices = 3;
  st.components = 2;
  st.threads = 1;
  Expected<Model> a = fit_model(table, st);
  st.threads = 2;
  Expected<Model> b = fit_model(table, st);
  ASSERT_TRUE(a.ok() && b.ok());
  for (std::size_t s = 0; s < a->slices.size(); ++s) {
    for (int c = 0; c < kChannels; ++c) {
      const ChannelSlice &x = a->slices[s].channel[std::size_t(c)],
                         &y = b->slices[s].channel[std::size_t(c)];
      ASSERT_EQ(x.components(), y.components());
      for (int r = 0; r < x.components(); ++r) {
        EXPECT_EQ(x.component(r).theta, y.component(r).theta);
        EXPECT_EQ(x.component(r).scale, y.component(r).scale);
        EXPECT_EQ(x.component(r).pdf_h, y.component(r).pdf_h);
      }
    }
    EXPECT_EQ(a->slices[s].channel[2].scale, 0.0);
    EXPECT_EQ(a->slices[s].channel[2].components(), 1);
  }
  const BrdfTable rec = a->table();
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (table.measured(c, i)) {
        ASSERT_TRUE(std::isfinite(rec.physical(c, i)) && rec.physical(c, i) >= 0);
      }
    }
  }
}

// Every component of every slice and channel equal, bit for bit.
void expect_same_model(const Model& a, const Model& b) {
  ASSERT_EQ(a.slices.size(), b.slices.size());
  for (std::size_t s = 0; s < a.slices.size(); ++s) {
    EXPECT_EQ(a.slices[s].theta_d_begin, b.slices[s].theta_d_begin);
    for (int c = 0; c < kChannels; ++c) {
      const ChannelSlice &x = a.slices[s].channel[std::size_t(c)],
                         &y = b.slices[s].channel[std::size_t(c)];
      ASSERT_EQ(x.components(), y.components()) << "slice " << s << " channel " << c;
      for (int r = 0; r < x.components(); ++r) {
        EXPECT_EQ(x.component(r).family, y.component(r).family);
        EXPECT_EQ(x.component(r).theta, y.component(r).theta);
        EXPECT_EQ(x.component(r).scale, y.component(r).scale);
        EXPECT_EQ(x.component(r).pdf_h, y.component(r).pdf_h);
        EXPECT_EQ(x.component(r).pdf_d, y.component(r).pdf_d);
        EXPECT_EQ(x.component(r).pdf_p, y.component(r).pdf_p);
      }
    }
  }
}

// The ladder (rate control's warm start) gives fit_model's model and report at every count, and
// spends each component's sweeps once: its total is what one fit at the largest count spends.
TEST(Mixture, FitLadderEqualsSeparateFitsAndReusesTheFactorization) {
  for (const char* sample : {"ggx-sharp", "near-mirror"}) {
    BrdfTable table = make_sample(sample).value();
    if (std::string(sample) == "near-mirror") {
      for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
        if (table.measured(2, i)) table.set_physical(2, i, 0.0);  // an all-zero channel
      }
    }
    FitSettings st;
    st.slices = 3;
    st.threads = 2;
    FitLadder ladder(table, st);
    long long sweeps_at_top = 0;
    // Three counts on the first sample, two on the second keep the test short.
    const int top = std::string(sample) == "near-mirror" ? 2 : 3;
    for (int k = 1; k <= top; ++k) {
      FitReport lr, fr;
      Expected<Model> from_ladder = ladder.fit(k, &lr);
      st.components = k;
      Expected<Model> alone = fit_model(table, st, &fr);
      ASSERT_TRUE(from_ladder.ok() && alone.ok()) << sample;
      SCOPED_TRACE(std::string(sample) + ", " + std::to_string(k) + " components");
      expect_same_model(*from_ladder, *alone);
      ASSERT_EQ(lr.slices.size(), fr.slices.size());
      sweeps_at_top = 0;
      for (std::size_t s = 0; s < lr.slices.size(); ++s) {
        for (int c = 0; c < kChannels; ++c) {
          const ChannelSliceFit &x = lr.slices[s][std::size_t(c)],
                                &y = fr.slices[s][std::size_t(c)];
          EXPECT_EQ(x.objective, y.objective);
          EXPECT_EQ(x.hals_sweeps, y.hals_sweeps);
          EXPECT_EQ(x.hals_unconverged, y.hals_unconverged);
          EXPECT_EQ(x.solver_iterations, y.solver_iterations);
          sweeps_at_top += y.hals_sweeps;
        }
      }
      EXPECT_EQ(ladder.fits(), k);
    }
    // fit_model at the top count counts the sweeps of every added component; so does the ladder
    // after fitting 1, 2, ... (without the warm start: component 2's again at 3).
    if (top == 3) {
      EXPECT_GT(sweeps_at_top, 0) << sample;
    }
    EXPECT_EQ(ladder.hals_sweeps(), sweeps_at_top) << sample;
    // Asking again is free; a count below the ladder's top is fitted on its own, still equal.
    FitReport again;
    EXPECT_TRUE(ladder.fit(2, &again).ok());
    EXPECT_EQ(ladder.fits(), top);
    EXPECT_EQ(ladder.fit(9).status().code(), ErrorCode::kInvalidArgument);
  }
  FitSettings bad;
  bad.slices = 0;
  const BrdfTable lambertian = make_sample("lambertian").value();
  FitLadder refused(lambertian, bad);
  EXPECT_EQ(refused.fit(1).status().code(), ErrorCode::kInvalidArgument);
}

// mixture_copulas = false (rate control's search) leaves every copula of a mixture at
// independence and fits no copula: the objective is the factorization's, never below the full
// fit's; the ladder gives fit_model's model with the setting too.
TEST(Mixture, MixturesWithoutCopulaFitKeepIndependenceAndTheFactorization) {
  const BrdfTable table = make_sample("ggx-sharp").value();
  FitSettings st;
  st.slices = 3;
  st.threads = 2;
  st.components = 2;
  FitReport full_report, plain_report;
  const Model full = fit_model(table, st, &full_report).value();
  st.mixture_copulas = false;
  const Model plain = fit_model(table, st, &plain_report).value();
  FitLadder ladder(table, st);
  expect_same_model(ladder.fit(2).value(), plain);
  int mixtures = 0, fitted_copulas = 0;
  for (std::size_t s = 0; s < plain.slices.size(); ++s) {
    for (int c = 0; c < kChannels; ++c) {
      const ChannelSlice& x = plain.slices[s].channel[std::size_t(c)];
      const ChannelSlice& y = full.slices[s].channel[std::size_t(c)];
      if (y.components() > 1) {
        for (int r = 0; r < y.components(); ++r) fitted_copulas += y.component(r).theta != 0.0;
      }
      EXPECT_LE(full_report.slices[s][std::size_t(c)].objective,
                plain_report.slices[s][std::size_t(c)].objective);
      if (x.components() < 2) continue;
      ++mixtures;
      for (int r = 0; r < x.components(); ++r) EXPECT_EQ(x.component(r).theta, 0.0);
    }
  }
  EXPECT_GT(mixtures, 0);
  EXPECT_GT(fitted_copulas, 0) << "the full fit should move some copula off independence";
}

TEST(Mixture, SettingsAreValidated) {
  const BrdfTable table = make_sample("lambertian").value();
  FitSettings st;
  st.components = 0;
  Expected<Model> m = fit_model(table, st);
  ASSERT_FALSE(m.ok());
  EXPECT_EQ(m.status().message(), "component count 0 is outside 1 to 8");
  st.components = 9;
  EXPECT_EQ(fit_model(table, st).status().message(), "component count 9 is outside 1 to 8");
  st.components = 2;
  st.auto_component_gain = 0;
  EXPECT_EQ(fit_model(table, st).status().message(), "auto_component_gain must lie in (0, 1]");
}

TEST(Mixture, EncodedFileIsVersion11AndDecodesToTheQuantizedModel) {
  EncoderSettings st = testing::encoder_1_2();
  st.fit.slices = 3;
  st.fit.components = 2;
  st.fit.threads = 2;
  st.container.bits = 12;
  const BrdfTable table = make_sample("plastic").value();
  Expected<EncodeResult> enc = encode_table(table, st);
  ASSERT_TRUE(enc.ok()) << enc.status().message();
  Expected<ContainerInfo> info = inspect_container(enc->bytes);
  ASSERT_TRUE(info.ok());
  EXPECT_EQ(info->layout.minor, 1);
  EXPECT_EQ(info->slices[0].components[0], 2);
  Expected<BrdfTable> dec = decode_table(enc->bytes);
  ASSERT_TRUE(dec.ok());
  // 12-bit marginals: the decoded table is the fitted model up to quantization.
  EXPECT_LT(rel_rmse(enc->model.table(), *dec), 5e-3);
  // And a one-component encode of the same table is version 1.0.
  st.fit.components = 1;
  Expected<EncodeResult> one = encode_table(table, st);
  ASSERT_TRUE(one.ok());
  EXPECT_EQ(inspect_container(one->bytes)->layout.minor, 0);
  EXPECT_LT(one->bytes.size(), enc->bytes.size());
}

}  // namespace
}  // namespace cbrdf
