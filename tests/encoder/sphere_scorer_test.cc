// SPDX-License-Identifier: MIT
// SphereScorer (metrics.h): rate control's and --bits auto's measurement. It renders a model from a
// few rows of its table instead of the whole table; its scores must equal sphere_psnr's on the
// decoded table bit for bit, or the search would choose differently from what a user measures.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "cbrdf/codec.h"
#include "cbrdf/encoder.h"
#include "cbrdf/samples.h"
#include "coding_1_2.h"
#include "metrics.h"

namespace cbrdf {
namespace {

// Equal bit for bit (NaN equal to NaN: an empty sphere scores NaN both ways).
void expect_same(double a, double b, const std::string& what) {
  if (std::isnan(a) && std::isnan(b)) return;
  EXPECT_EQ(a, b) << what;
}

void expect_same_metrics(const ImageMetrics& a, const ImageMetrics& b) {
  expect_same(a.psnr_linear, b.psnr_linear, "linear");
  expect_same(a.psnr_tonemapped, b.psnr_tonemapped, "tone-mapped");
  ASSERT_EQ(a.per_light.size(), b.per_light.size());
  for (std::size_t l = 0; l < a.per_light.size(); ++l) {
    EXPECT_EQ(a.per_light[l].exposure, b.per_light[l].exposure);
    for (int c = 0; c < 3; ++c) {
      expect_same(a.per_light[l].psnr_linear[c], b.per_light[l].psnr_linear[c], "light linear");
      expect_same(a.per_light[l].psnr_tonemapped[c], b.per_light[l].psnr_tonemapped[c],
                  "light tone-mapped");
    }
  }
}

// The decoded file of `table` at these counts (as rate control measures it).
Model decoded(const BrdfTable& table, int components, bool copulas, double max_error = 0) {
  EncoderSettings st = testing::encoder_1_2();
  st.fit.slices = 3;
  st.fit.threads = 2;
  st.fit.impute_iterations = 2;
  st.fit.components = components;
  st.fit.mixture_copulas = copulas;
  st.container.bits = 8;
  st.residual.max_error = max_error;
  auto encoded = encode_table(table, st);
  if (!encoded.ok()) {
    ADD_FAILURE() << encoded.status().message();
    return {};
  }
  auto model = decode_model(encoded->bytes);
  if (!model.ok()) {
    ADD_FAILURE() << model.status().message();
    return {};
  }
  return *model;
}

TEST(SphereScorer, ScoresEqualSpherePsnrOnTheDecodedTable) {
  // near-mirror has not-measured bins where the spheres look, and a peak far from the rest.
  for (const char* sample : {"ggx-rough", "near-mirror"}) {
    SCOPED_TRACE(sample);
    const BrdfTable table = make_sample(sample).value();
    const SphereScorer scorer(table);
    for (int components : {1, 2}) {
      for (bool copulas : {true, false}) {
        if (components == 1 && !copulas) continue;
        SCOPED_TRACE(std::to_string(components) + " components, copulas " +
                     std::to_string(copulas));
        const Model m = decoded(table, components, copulas);
        const BrdfTable t = m.table();
        const ImageMetrics expected = sphere_psnr(table, t);
        expect_same_metrics(scorer.score(m), expected);
        expect_same_metrics(scorer.score(t), expected);
      }
    }
  }
}

TEST(SphereScorer, ResidualScaledAndOtherSetupsToo) {
  const BrdfTable table = make_sample("ggx-rough").value();
  // A residual layer is scored through the table.
  const Model with_residual = decoded(table, 1, true, 0.05);
  ASSERT_TRUE(with_residual.residual.present());
  expect_same_metrics(SphereScorer(table).score(with_residual),
                      sphere_psnr(table, with_residual.table()));
  // Values near 1e-200: renders are scaled by a power of two first.
  BrdfTable tiny = table;
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (tiny.measured(c, i)) tiny.set_physical(c, i, table.physical(c, i) * 1e-200);
    }
  }
  const Model m = decoded(tiny, 1, true);
  expect_same_metrics(SphereScorer(tiny).score(m), sphere_psnr(tiny, m.table()));
  // Another size and lights, and a size with no sphere at all.
  const Model plain = decoded(table, 1, true);
  for (const SphereSetup& setup : {SphereSetup{64, {0, 30, 80}, 2}, SphereSetup{0, {45}, 1}}) {
    SCOPED_TRACE("size " + std::to_string(setup.size));
    expect_same_metrics(SphereScorer(table, setup).score(plain),
                        sphere_psnr(table, plain.table(), setup));
  }
}

}  // namespace
}  // namespace cbrdf
