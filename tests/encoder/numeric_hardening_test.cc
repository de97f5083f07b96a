// SPDX-License-Identifier: MIT
// Numeric hardening: a valid file decodes with bounded work per bin whatever its parameters, the
// fit does not depend on the table's overall scale, tables outside the supported value range are
// refused in the user's terms, and sphere PSNR never reports a wrong result as a perfect match
// (spec/container.md, "Resource bounds"). Work is bounded by counting evaluations that leave the
// fast path, never by timing.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "cbrdf/codec.h"
#include "cbrdf/encoder.h"
#include "cbrdf/samples.h"
#include "coding_1_2.h"
#include "density/grid_copula.h"
#include "fit/mixture.h"
#include "metrics.h"
#include "synthetic_model.h"

namespace cbrdf {
namespace {

constexpr double kDblMax = std::numeric_limits<double>::max();
constexpr double kTiny = std::numeric_limits<double>::denorm_min();

// Every slice and channel of a six-slice model with one family and parameter, and `components`
// copies of the component.
Model uniform_model(CopulaFamily family, double theta, int components = 1) {
  Model m = testing::make_model(testing::six_slices());
  for (Slice& s : m.slices) {
    for (ChannelSlice& cs : s.channel) {
      cs.family = family;
      cs.theta = theta;
      cs.extra.assign(std::size_t(components - 1), static_cast<const Component&>(cs));
    }
  }
  return m;
}

// Through a file where the format holds the parameters; beyond its ranges (spec 4.2, issue 31)
// the writer refuses them, and the model is evaluated as it is, as a library caller's may be.
Model through_file(const Model& m) {
  Expected<std::vector<std::uint8_t>> bytes = encode_model(m, testing::coding_1_2());
  if (!bytes.ok()) {
    EXPECT_EQ(bytes.status().code(), ErrorCode::kInvalidArgument) << bytes.status().message();
    return m;
  }
  Expected<Model> back = decode_model(*bytes);
  EXPECT_TRUE(back.ok()) << back.status().message();
  return std::move(back).value();
}

// Every 7th bin of every channel through bin_value (the per-bin path table() shares).
std::vector<double> sampled_values(const Model& m) {
  const ModelEvaluator ev(m);
  std::vector<double> out;
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; i += 7) {
      const BinIndex b = merl_bin(i);
      out.push_back(ev.bin_value(c, b.theta_h, b.theta_d, b.phi_d));
    }
  }
  return out;
}

struct Case {
  CopulaFamily family;
  double theta;
};

// Each family's domain edges and extremes, including subnormal distances from independence.
std::vector<Case> extreme_parameters() {
  std::vector<Case> cases;
  for (double t : {-kDblMax, -1e300, -1e10, -1e4, -745.0, -200.5, -200.0, -kTiny, 0.0, kTiny,
                   0.6931471805599453}) {
    cases.push_back({CopulaFamily::kFrank, t});
  }
  for (double t : {0.0, kTiny, 1e-300, 50.0, 1e4, 1e300, kDblMax}) {
    cases.push_back({CopulaFamily::kClayton, t});
  }
  for (CopulaFamily f : {CopulaFamily::kGumbel, CopulaFamily::kJoe}) {
    for (double t : {1.0, 1.0 + 0x1p-52, 20.0, 1e3, 1e4, 1e10, 1e300, kDblMax}) {
      cases.push_back({f, t});
    }
  }
  cases.push_back({CopulaFamily::kIndependence, 0.0});
  return cases;
}

// Before the fix, Frank at -DBL_MAX and Joe above 1e3 sent almost every bin through the general
// log_density (about 400 ns a bin against 5 to 40 ns): a 430-byte file took 35 s to decode.
TEST(DecodeWork, NoBinLeavesForTheGeneralPathAtAnyParameter) {
  for (const Case& c : extreme_parameters()) {
    SCOPED_TRACE(std::string(family_name(c.family)) + " " + std::to_string(c.theta));
    const Model m = through_file(uniform_model(c.family, c.theta));
    internal::grid_work_counters() = {};
    const std::vector<double> v = sampled_values(m);
    EXPECT_EQ(internal::grid_work_counters().general_paths, 0u);
    for (double x : v) ASSERT_TRUE(std::isfinite(x) && x >= 0.0) << x;
  }
}

TEST(DecodeWork, OrdinaryModelsStayOnTheFastPath) {
  const Model m = through_file(testing::make_mixture_model(testing::six_slices(), 3));
  internal::grid_work_counters() = {};
  const BrdfTable t = m.table();
  EXPECT_EQ(internal::grid_work_counters().log_sum_paths, 0u);
  EXPECT_EQ(internal::grid_work_counters().general_paths, 0u);
}

// Parameters beyond +-1e300 are evaluated at +-1e300 (spec section 7).
TEST(DecodeWork, ParametersBeyondTheEvaluationRangeDecodeAsItsEnd) {
  const Case pairs[][2] = {
      {{CopulaFamily::kFrank, -kDblMax}, {CopulaFamily::kFrank, -1e300}},
      {{CopulaFamily::kClayton, kDblMax}, {CopulaFamily::kClayton, 1e300}},
      {{CopulaFamily::kGumbel, kDblMax}, {CopulaFamily::kGumbel, 1e300}},
      {{CopulaFamily::kJoe, kDblMax}, {CopulaFamily::kJoe, 1e300}},
  };
  for (const auto& p : pairs) {
    SCOPED_TRACE(std::string(family_name(p[0].family)));
    EXPECT_EQ(sampled_values(through_file(uniform_model(p[0].family, p[0].theta))),
              sampled_values(through_file(uniform_model(p[1].family, p[1].theta))));
  }
}

// The file: 8 Frank components at -DBL_MAX in every slice and channel. Every bin of the
// full table takes the bounded log-sum path (a few exp and a log), none the general one.
TEST(DecodeWork, EightComponentsAtMinusDblMaxHaveBoundedWork) {
  const Model m = through_file(uniform_model(CopulaFamily::kFrank, -kDblMax, 8));
  internal::grid_work_counters() = {};
  const BrdfTable t = m.table();
  EXPECT_EQ(internal::grid_work_counters().general_paths, 0u);
  EXPECT_LE(internal::grid_work_counters().log_sum_paths, 8u * kChannels * kBinsPerChannel);
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      const double v = t.channel_data(c)[i];
      ASSERT_TRUE(std::isfinite(v));
    }
  }
}

BrdfTable scaled(const BrdfTable& t, double k) {
  BrdfTable out = t;
  for (double& v : out.stored_values()) {
    if (v >= 0) v *= k;
  }
  return out;
}

struct FitAtScale {
  Model model;
  int sweeps = 0, iterations = 0, unconverged = 0;
};

FitAtScale fit_at(const BrdfTable& base, double k) {
  EncoderSettings st = testing::encoder_1_2();
  st.fit.components = 2;
  st.fit.slices = 3;
  Expected<EncodeResult> r = encode_table(scaled(base, k), st);
  EXPECT_TRUE(r.ok()) << r.status().message();
  FitAtScale out;
  out.model = r->model;
  for (const auto& s : r->report.slices) {
    for (const ChannelSliceFit& c : s) {
      out.sweeps += c.hals_sweeps;
      out.iterations += c.solver_iterations;
      out.unconverged += c.hals_unconverged;
    }
  }
  return out;
}

// Before the fix a mixture fit took 60 s (1e100, 1e-100) to 600 s (1e300) instead of 2 s: sums of
// squares overflowed or lost precision and every factorization ran to its sweep cap.
TEST(FitScale, MixtureFitDoesNotDependOnTheTableScale) {
  const BrdfTable base = make_sample("plastic").value();
  const FitAtScale ref = fit_at(base, 1.0);
  EXPECT_GT(ref.sweeps, 0);
  // Bounded: at most kMaxSweeps per added component, every slice and channel.
  EXPECT_LE(ref.sweeps, internal::kMaxSweeps * 3 * kChannels);
  for (double k : {0x1p-330, 0x1p330, 0x1p-600, 0x1p600, 1e-100, 1e100, 1e200}) {
    SCOPED_TRACE(k);
    const FitAtScale f = fit_at(base, k);
    EXPECT_EQ(f.sweeps, ref.sweeps);
    EXPECT_EQ(f.iterations, ref.iterations);
    EXPECT_EQ(f.unconverged, ref.unconverged);
    const bool power_of_two = std::ilogb(k) == std::log2(k);
    ASSERT_EQ(f.model.slices.size(), ref.model.slices.size());
    for (std::size_t s = 0; s < ref.model.slices.size(); ++s) {
      for (int c = 0; c < kChannels; ++c) {
        const ChannelSlice &a = f.model.slices[s].channel[c], &b = ref.model.slices[s].channel[c];
        ASSERT_EQ(a.components(), b.components());
        for (int r = 0; r < a.components(); ++r) {
          const Component &x = a.component(r), &y = b.component(r);
          if (power_of_two) {  // the normalization is exact: the same fit, bit for bit
            EXPECT_EQ(x.theta, y.theta);
            EXPECT_EQ(x.scale, y.scale * k);
            EXPECT_EQ(x.pdf_h, y.pdf_h);
          } else {
            EXPECT_NEAR(x.theta, y.theta, 1e-9 * (1 + std::abs(y.theta)));
            EXPECT_NEAR(x.scale / k, y.scale, 1e-9 * y.scale);
          }
        }
      }
    }
  }
}

BrdfTable constant_table(double v) {
  BrdfTable t = make_sample("lambertian").value();
  for (double& x : t.stored_values()) {
    if (x >= 0) x = v;
  }
  return t;
}

double relative_rmse(const BrdfTable& ref, const BrdfTable& test) {
  double num = 0, den = 0;
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (!ref.measured(c, i)) continue;
      const double a = ref.channel_data(c)[i], b = test.channel_data(c)[i];
      num += (a - b) * (a - b);
      den += a * a;
    }
  }
  return std::sqrt(num / den);
}

// Before the fix 1e300 times a material decoded 13,000 to 44,000 bins to the largest double (up
// to 195 times too large), all-DBL_MAX failed with "scale K -nan is not a finite value" and
// all-5e-324 decoded to zeros, each reported at 100 dB.
TEST(ValueRange, OutOfRangeTablesAreRefusedInTheUsersTerms) {
  EncoderSettings st = testing::encoder_1_2();
  st.fit.slices = 2;
  const BrdfTable plastic = make_sample("plastic").value();
  for (const BrdfTable& t : {scaled(plastic, 1e300), constant_table(kDblMax), constant_table(kTiny),
                             scaled(plastic, 1e-260)}) {
    Expected<EncodeResult> r = encode_table(t, st);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.status().code(), ErrorCode::kNumeric);
    EXPECT_NE(r.status().message().find("largest measured value"), std::string::npos)
        << r.status().message();
    EXPECT_NE(r.status().message().find("supported range (1e-250 to 1e+250"), std::string::npos)
        << r.status().message();
  }
}

TEST(ValueRange, TablesInsideTheRangeDecodeFaithfully) {
  EncoderSettings st = testing::encoder_1_2();
  st.fit.slices = 2;
  const BrdfTable plastic = make_sample("plastic").value();
  Expected<EncodeResult> ref = encode_table(plastic, st);
  ASSERT_TRUE(ref.ok());
  const BrdfTable ref_decoded = decode_table(ref->bytes).value();
  // The largest measured value of plastic is about 3.6e6: these reach 3.6e249 and 3.6e-244.
  for (double k : {1e243, 1e-250}) {
    SCOPED_TRACE(k);
    Expected<EncodeResult> r = encode_table(scaled(plastic, k), st);
    ASSERT_TRUE(r.ok()) << r.status().message();
    const BrdfTable decoded = decode_table(r->bytes).value();
    EXPECT_LT(relative_rmse(ref_decoded, scaled(decoded, 1 / k)), 1e-12);
    const ImageMetrics a = sphere_psnr(plastic, ref_decoded);
    const ImageMetrics b = sphere_psnr(scaled(plastic, k), decoded);
    EXPECT_NEAR(a.psnr_linear, b.psnr_linear, 1e-3);
    EXPECT_NEAR(a.psnr_tonemapped, b.psnr_tonemapped, 1e-3);
    EXPECT_LT(b.psnr_tonemapped, kPsnrCapDb);
  }
  // A table of zeros is represented exactly.
  Expected<EncodeResult> zero = encode_table(constant_table(0.0), st);
  ASSERT_TRUE(zero.ok()) << zero.status().message();
  const BrdfTable z = decode_table(zero->bytes).value();
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (z.measured(c, i)) {
        ASSERT_EQ(z.channel_data(c)[i], 0.0);
      }
    }
  }
}

// A wrong result is never 100 dB: neither overflowed float renders (inf - inf is NaN, which
// std::min(100, NaN) turned into 100) nor underflowed ones (all 0).
TEST(PsnrRange, WrongResultsAtExtremeMagnitudesAreNotPerfect) {
  const BrdfTable plastic = make_sample("plastic").value();
  const BrdfTable huge = scaled(plastic, 1e300);
  BrdfTable saturated = huge;  // as the decoder gave it before: large values saturated
  for (double& v : saturated.stored_values()) {
    if (v > 1e300) v = kDblMax;
  }
  const ImageMetrics a = sphere_psnr(huge, saturated);
  EXPECT_LT(a.psnr_linear, kPsnrCapDb);
  EXPECT_LT(a.psnr_tonemapped, kPsnrCapDb);
  const ImageMetrics fn = sphere_psnr(nearest_lookup_fn(huge), nearest_lookup_fn(saturated));
  EXPECT_LT(fn.psnr_linear, kPsnrCapDb);
  EXPECT_EQ(fn.psnr_linear, a.psnr_linear);

  // (Stored 1e-300 is 6.7e-304 in physical units; 5e-324 would be 0 there, a real match.)
  const ImageMetrics b = sphere_psnr(constant_table(1e-300), constant_table(0.0));
  EXPECT_LT(b.psnr_linear, kPsnrCapDb);
  EXPECT_LT(b.psnr_tonemapped, kPsnrCapDb);

  // Right results stay perfect, and ordinary ones do not move with the scale.
  EXPECT_EQ(sphere_psnr(huge, huge).psnr_linear, kPsnrCapDb);
  BrdfTable noisy = plastic;
  for (double& v : noisy.stored_values()) {
    if (v > 0) v *= 1.01;
  }
  const ImageMetrics p1 = sphere_psnr(plastic, noisy);
  const ImageMetrics p2 = sphere_psnr(scaled(plastic, 0x1p900), scaled(noisy, 0x1p900));
  EXPECT_EQ(p1.psnr_linear, p2.psnr_linear);
  EXPECT_EQ(p1.psnr_tonemapped, p2.psnr_tonemapped);
  EXPECT_LT(p1.psnr_linear, kPsnrCapDb);

  Image x(2, 2), y(2, 2);
  y.data[0] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(psnr(x, y, 0, 1.0), -std::numeric_limits<double>::infinity());
  x.data[0] = y.data[0] = std::numeric_limits<float>::infinity();
  EXPECT_EQ(psnr(x, y, 0, 1.0), kPsnrCapDb);
}

}  // namespace
}  // namespace cbrdf
