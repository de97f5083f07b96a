// SPDX-License-Identifier: MIT
// Targets no file can meet, on valid tables far from any BRDF (issue 40, item 7): values
// log-uniform over 60 and 480 decades (the largest within the supported 1e-250..1e250), and a
// checkerboard of 1e-240 and 1e240. The noise estimate stays finite or says it cannot measure
// (NaN, never an infinity); the bound derived from it stays inside what a file holds; and
// --target-psnr and --target-bytes end with the closest file (met false), never an error.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "cbrdf/cbrdf_c.h"
#include "cbrdf/codec.h"
#include "cbrdf/coords.h"
#include "cbrdf/encoder.h"
#include "cbrdf/noise.h"
#include "cbrdf/rate_control.h"
#include "coding_1_2.h"
#include "table_builder.h"

namespace cbrdf {
namespace {

using testing::log_uniform_table;

struct Case {
  const char* name;
  double lo, hi;
};
const Case kCases[] = {{"1e-30..1e30", 1e-30, 1e30}, {"1e-240..1e240", 1e-240, 1e240}};

// A ceiling is a finite dB value or NaN: not measurable.
void expect_finite_or_not_measurable(double ceiling, const char* what) {
  EXPECT_TRUE(std::isfinite(ceiling) || std::isnan(ceiling)) << what << " is " << ceiling;
}

TEST(UnreachableTarget, NoiseFloorIsFiniteOrNotMeasurable) {
  for (const Case& k : kCases) {
    SCOPED_TRACE(k.name);
    const NoiseEstimate e = estimate_noise(log_uniform_table(k.lo, k.hi, 40));
    EXPECT_TRUE(e.noisy());
    for (double s : e.sigma) EXPECT_TRUE(std::isfinite(s) && s > 1) << s;
    expect_finite_or_not_measurable(e.psnr_ceiling_tonemapped, "the tone-mapped ceiling");
    expect_finite_or_not_measurable(e.psnr_ceiling_linear, "the linear ceiling");
    // The noise, thousands of percent per bin, overflows the linear renders of its simulated draw.
    EXPECT_TRUE(std::isnan(e.psnr_ceiling_linear)) << e.psnr_ceiling_linear;
    // The floor's bound is one a file can hold (RESD: 1e-6 to 16), however large the noise.
    const double floor = noise_floor_error(e);
    EXPECT_GE(floor, 1e-6);
    EXPECT_LE(floor, 16.0);
  }
}

// The C API passes the sentinel on: NaN, documented in cbrdf_encode.h, never an infinity.
TEST(UnreachableTarget, CApiNoiseFloorIsFiniteOrNaN) {
  const BrdfTable table = log_uniform_table(1e-30, 1e30, 40);
  cbrdf_noise_estimate e{};
  e.struct_size = sizeof e;
  ASSERT_EQ(cbrdf_estimate_noise(table.stored_values().data(), table.stored_values().size(), &e),
            CBRDF_OK)
      << cbrdf_last_error_message();
  EXPECT_EQ(e.noisy, 1);
  EXPECT_TRUE(std::isfinite(e.psnr_ceiling_tonemapped)) << e.psnr_ceiling_tonemapped;
  EXPECT_TRUE(std::isnan(e.psnr_ceiling_linear)) << e.psnr_ceiling_linear;
}

// The chosen file is what the result says it is.
void expect_closest_file(const Expected<RateResult>& r) {
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_FALSE(r->met);
  EXPECT_EQ(double(r->encoded.bytes.size()), r->chosen.bytes);
  auto decoded = decode_table(r->encoded.bytes);
  ASSERT_TRUE(decoded.ok()) << decoded.status().message();
}

EncoderSettings three_slices() {
  EncoderSettings st = testing::encoder_1_2();
  st.fit.threads = 2;
  st.fit.slices = 3;
  return st;
}

// A PSNR far above what any file reaches on such a table: the closest file, and a note saying
// why. (The wider table takes the same path: its floor, clamped as above, is the largest bound.)
TEST(UnreachableTarget, PsnrTargetEndsWithTheClosestFile) {
  auto r =
      encode_to_target_ladder(log_uniform_table(1e-30, 1e30, 40), three_slices(), {0, 50, 1, {3}});
  expect_closest_file(r);
  ASSERT_TRUE(r.ok());
  // The noise floor, 0.5 sigma = 21, is more than a file holds: the residual stops at 16, or the
  // model alone is as close to the smoothed signal.
  EXPECT_LE(r->chosen.max_error, 16.0);
  EXPECT_EQ(r->note.rfind("the input is noisy (about 42", 0), 0u) << r->note;
}

// A smooth (by the noise estimate) checkerboard over theta_h and theta_d of 1e-240 and 1e240: no
// model follows it, and no residual layer can be written on it, even at the largest bound (the
// bins lie hundreds of e-folds from the model): the model alone, and the note says why.
TEST(UnreachableTarget, TableNoResidualCanHoldEndsWithTheModelAlone) {
  BrdfTable t;
  for (int th = 0; th < kThetaHBins; ++th) {
    for (int td = 0; td < kThetaDBins; ++td) {
      for (int p = 0; p < kPhiDBins; ++p) {
        for (int c = 0; c < kChannels; ++c) {
          t.set_physical(c, merl_index(th, td, p), (th + td) % 2 ? 1e-240 : 1e240);
        }
      }
    }
  }
  auto r = encode_to_target_ladder(t, three_slices(), {0, 50, 1, {3}});
  expect_closest_file(r);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->chosen.max_error, 0.0);
  EXPECT_NE(r->note.find("no residual layer can be written on this table, even at the largest "
                         "bound 16"),
            std::string::npos)
      << r->note;
}

TEST(UnreachableTarget, ByteBudgetEndsWithTheClosestFileOrMeetsIt) {
  const BrdfTable table = log_uniform_table(1e-30, 1e30, 41);
  // A budget too small for any file.
  expect_closest_file(encode_to_target_ladder(table, three_slices(), {100, 0, 1, {3}}));
  // A budget with room for a residual: met, within it.
  auto roomy = encode_to_target_ladder(table, three_slices(), {2e6, 0, 1, {3}});
  ASSERT_TRUE(roomy.ok()) << roomy.status().message();
  EXPECT_TRUE(roomy->met);
  EXPECT_LE(roomy->encoded.bytes.size(), std::size_t{2000000});
  // The residual at the noise floor, 21 clamped to the largest bound a file holds.
  EXPECT_EQ(roomy->chosen.max_error, 16.0);
  EXPECT_EQ(roomy->note.rfind("the input is noisy", 0), 0u) << roomy->note;
}

}  // namespace
}  // namespace cbrdf
