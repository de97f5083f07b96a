// SPDX-License-Identifier: MIT
// `cbrdf report --sampling` (report/sampling_study.h): the variance study of importance sampling
// against the measured table, on a built-in measured fabric.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "cbrdf/codec.h"
#include "cbrdf/encoder.h"
#include "cbrdf/samples.h"
#include "report/sampling_study.h"
#include "test_support.h"

namespace cbrdf {
namespace {
using testing::CommandResult;
using testing::contains;
using testing::run_cli;

struct Felt {
  BrdfTable table;
  Model model;
};

const Felt& felt() {
  static const Felt f = [] {
    Expected<BrdfTable> table = make_sample("pink-felt");
    EXPECT_TRUE(table.ok());
    Expected<EncodeResult> encoded = encode_table(*table, EncoderSettings{});
    EXPECT_TRUE(encoded.ok());
    Expected<Model> model = decode_model(encoded->bytes);
    EXPECT_TRUE(model.ok());
    return Felt{std::move(*table), std::move(*model)};
  }();
  return f;
}

// The three samplers estimate the same albedo; cbrdf's is no worse than cosine at any elevation,
// where the 2.2 sampler (min_table_gain 0) was worse at normal incidence; the reference is best.
TEST(ReportSampling, FeltIsNoWorseThanCosineAndThe22SamplerWas) {
  report::SamplingStudySettings st;
  st.draws = 40000;
  auto rows = report::sampling_study("pink-felt", felt().table, felt().model, st);
  ASSERT_TRUE(rows.ok()) << rows.status().message();
  ASSERT_EQ(rows->size(), 4u);
  for (const report::SamplingRow& r : *rows) {
    const double se =
        std::sqrt(r.cosine.variance / st.draws) + std::sqrt(r.cbrdf.variance / st.draws);
    EXPECT_NEAR(r.cosine.mean, r.cbrdf.mean, 5 * se) << r.elevation_deg;
    EXPECT_NEAR(r.cosine.mean, r.tabulated.mean,
                5 * se + 5 * std::sqrt(r.tabulated.variance / st.draws))
        << r.elevation_deg;
    EXPECT_GE(r.gain(), 1.0) << r.elevation_deg;
    EXPECT_LT(r.tabulated.variance, r.cosine.variance) << r.elevation_deg;
    EXPECT_GT(r.cbrdf.draws_per_second, 0.0);
  }
  st.sampler.min_table_gain = 0;
  st.elevations_deg = {0};
  auto old = report::sampling_study("pink-felt", felt().table, felt().model, st);
  ASSERT_TRUE(old.ok());
  EXPECT_LT(old->front().gain(), 1.0);
  const std::string csv = report::sampling_csv(*rows);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 5);
  EXPECT_TRUE(contains(report::sampling_summary(*rows), "pink-felt"));
  EXPECT_EQ(report::sampling_table(*rows).rows.size(), 4u);
}

// The settings are checked before anything is tabulated or drawn.
TEST(ReportSampling, RefusesFewDrawsAndElevationsOutsideTheHemisphere) {
  const BrdfTable table;
  const Model model;
  report::SamplingStudySettings st;
  st.draws = 1;
  auto few = report::sampling_study("pink-felt", table, model, st);
  ASSERT_FALSE(few.ok());
  EXPECT_EQ(few.status().message(), "sampling study: draws must be at least 2, not 1");
  st.draws = 10;
  st.elevations_deg = {90};
  auto grazing = report::sampling_study("pink-felt", table, model, st);
  ASSERT_FALSE(grazing.ok());
  EXPECT_TRUE(contains(grazing.status().message(), "not 90.00")) << grazing.status().message();
}

TEST(ReportSampling, CommandRefusesBadDraws) {
  const CommandResult r = run_cli("report --sampling --builtin --draws 1");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.err, "--draws")) << r.err;
}

}  // namespace
}  // namespace cbrdf
