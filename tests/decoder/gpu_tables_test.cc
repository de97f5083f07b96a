// SPDX-License-Identifier: MIT
// gpu_tables() and copula_density_plane() (cbrdf/gpu_tables.h) on golden files: the layout's
// header, slice map and descriptors, every product-form slot's constants and theta_h terms in
// their group and lane, the volumes present exactly when the model needs them; a slice's copula
// density plane against the copula's normalization.
#include "cbrdf/gpu_tables.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "cbrdf/codec.h"
#include "eval/product_form.h"

namespace cbrdf {
namespace {

// Product-form and generic components, mixtures, a residual layer.
std::vector<std::string> golden_files() {
  std::vector<std::string> out;
  for (const char* name :
       {"v1.0-frank6-b10", "v1.0-mixed2-b16", "v1.1-mixture3-b12", "v1.3-residual-frank6-b10"}) {
    out.push_back(std::string(CBRDF_TEST_DATA_DIR) + "/golden/" + name + ".cbrdf");
  }
  return out;
}

TEST(GpuTables, LayoutOfGoldenFiles) {
  int with_generic = 0, with_residual = 0;
  for (const std::string& path : golden_files()) {
    SCOPED_TRACE(path);
    auto m = decode_model_file(path);
    ASSERT_TRUE(m.ok()) << m.status().message();
    const Model& model = *m;
    const GpuTables g = gpu_tables(model);
    const std::vector<float>& t = g.tables;
    ASSERT_GE(t.size(), 106u);
    EXPECT_EQ(t.size() % 4, 0u);
    EXPECT_EQ(t[0], float(kGpuTablesLayout));
    EXPECT_EQ(t[1], float(model.slices.size()));
    const Residual& res = model.residual;
    EXPECT_EQ(t[2], !res.present() ? 0.0f : (res.exact ? 2.0f : 1.0f));
    EXPECT_EQ(g.residual.size(), res.present() ? 3 * kBinsPerChannel : 0u);
    EXPECT_EQ(g.generic.size(), t[4] == 1.0f ? 3 * kBinsPerChannel : 0u);
    for (int j = 0; j < kThetaDBins; ++j) EXPECT_EQ(t[std::size_t(16 + j)], model.slice_of(j));
    EXPECT_EQ(g.bytes(), (t.size() + g.generic.size() + g.residual.size()) * sizeof(float));

    bool any_generic = false;
    std::size_t next = (106 + 8 * model.slices.size() + 3) / 4 * 4;  // the first slice's rows
    for (std::size_t s = 0; s < model.slices.size(); ++s) {
      const Slice& slice = model.slices[s];
      const float* d = t.data() + 106 + 8 * s;
      int R = 1;
      for (const ChannelSlice& cs : slice.channel) R = std::max(R, cs.components());
      const int G = (3 * R + 3) / 4;
      const std::size_t row = std::size_t(G) * 12;
      EXPECT_EQ(d[0], float(slice.theta_d_begin));
      EXPECT_EQ(d[1], float(slice.theta_d_end));
      ASSERT_EQ(d[2], float(R));
      ASSERT_EQ(d[3], float(G));
      const std::size_t off_h = std::size_t(d[4]), off_d = std::size_t(d[5]);
      const std::size_t off_p = std::size_t(d[6]), off_k = std::size_t(d[7]);
      EXPECT_EQ(off_h, next);
      EXPECT_EQ(off_h % 4, 0u);
      EXPECT_EQ(off_d, off_h + 91 * row);
      EXPECT_EQ(off_p, off_d + std::size_t(slice.width() + 1) * row);
      EXPECT_EQ(off_k, off_p + 181 * row);
      next = off_k + std::size_t(G) * 28;
      ASSERT_LE(next, t.size());
      for (int c = 0; c < kChannels; ++c) {
        const ChannelSlice& cs = slice.channel[std::size_t(c)];
        for (int r = 0; r < cs.components(); ++r) {
          const Component& comp = cs.component(r);
          const internal::ProductForm f = internal::product_form(comp);
          if (!f.ok) {
            any_generic = true;
            continue;
          }
          if (comp.scale == 0.0) continue;
          const int q = c * R + r;
          const std::size_t lane = std::size_t(q / 4) * 28 + std::size_t(q % 4);
          const double kv[7] = {f.k.k, f.k.a0, f.k.a1, f.k.a2, f.k.b0, f.k.b1, f.k.b2};
          for (int e = 0; e < 7; ++e) EXPECT_EQ(t[off_k + lane + 4 * std::size_t(e)], float(kv[e]));
          std::vector<internal::AxisTerms<double>> terms;
          internal::axis_terms(f, comp.pdf_h, &terms);
          const std::size_t slot = std::size_t(q / 4) * 12 + std::size_t(q % 4);
          for (int i = 0; i <= kThetaHBins; ++i) {
            const auto& a = terms[std::size_t(std::min(i, kThetaHBins - 1))];
            const float* at = t.data() + off_h + std::size_t(i) * row + slot;
            ASSERT_EQ(at[0], float(a.g)) << "slice " << s << " slot " << q << " bin " << i;
            ASSERT_EQ(at[4], float(a.w));
            ASSERT_EQ(at[8], float(a.y));
          }
        }
      }
    }
    EXPECT_EQ(next, t.size());
    EXPECT_EQ(t[4], any_generic ? 1.0f : 0.0f);
    with_generic += any_generic;
    with_residual += res.present();
  }
  EXPECT_GT(with_generic, 0);  // the files cover both volumes
  EXPECT_GT(with_residual, 0);
}

// The copula's marginals are uniform: at any theta_d bin, the density summed over the other two
// axes with their bin masses is about 1 (a midpoint rule over the bins).
TEST(GpuTables, CopulaDensityPlaneIsNormalized) {
  auto m = decode_model_file(std::string(CBRDF_TEST_DATA_DIR) + "/golden/v1.0-frank6-b10.cbrdf");
  ASSERT_TRUE(m.ok()) << m.status().message();
  int dependent = 0;
  for (const Slice& slice : m->slices) {
    const Component& c = slice.channel[0];
    EXPECT_TRUE(copula_density_plane(c, -1).empty());
    EXPECT_TRUE(copula_density_plane(c, slice.width()).empty());
    const std::vector<double> plane = copula_density_plane(c, slice.width() / 2);
    ASSERT_EQ(plane.size(), std::size_t(kThetaHBins) * kPhiDBins);
    double sum = 0.0, lo = plane[0], hi = plane[0];
    for (int i = 0; i < kThetaHBins; ++i) {
      for (int k = 0; k < kPhiDBins; ++k) {
        const double v = plane[std::size_t(i) * kPhiDBins + std::size_t(k)];
        ASSERT_TRUE(std::isfinite(v) && v >= 0.0) << v;
        sum += c.pdf_h[std::size_t(i)] * c.pdf_p[std::size_t(k)] * v;
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
    }
    EXPECT_NEAR(sum, 1.0, 0.05);
    if (c.family != CopulaFamily::kIndependence && hi > 1.01 * lo) ++dependent;
  }
  EXPECT_GT(dependent, 0);

  Component independent;
  independent.family = CopulaFamily::kIndependence;
  independent.pdf_h.assign(kThetaHBins, 1.0 / kThetaHBins);
  independent.pdf_d.assign(4, 0.25);
  independent.pdf_p.assign(kPhiDBins, 1.0 / kPhiDBins);
  const std::vector<double> ones = copula_density_plane(independent, 3);
  ASSERT_EQ(ones.size(), std::size_t(kThetaHBins) * kPhiDBins);
  for (const double v : ones) ASSERT_EQ(v, 1.0);
}

}  // namespace
}  // namespace cbrdf
