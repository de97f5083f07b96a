// SPDX-License-Identifier: MIT
// gpu_tables() and copula_density_plane() (cbrdf/gpu_tables.h). The tables are built as
// eval/interp_tables.cc builds its float64 ones, then rounded to float as it does for eval_f32:
// the same product form, midpoint CDFs and terms. The viewer's browser test (tests/viewer)
// compares the shader with the native eval_f32, so a divergence fails there.
#include "cbrdf/gpu_tables.h"

#include <algorithm>
#include <cstddef>
#include <utility>

#include "density/grid_copula.h"
#include "eval/product_form.h"

namespace cbrdf {
namespace {

constexpr int kHeader = 16;
constexpr int kSliceDescriptor = 8;
using internal::kGroup, internal::kGroupConstants, internal::kGroupTerms;
using internal::ProductForm;

// Slot q's (g, w, y) per bin into rows of `row` floats at `base`, bins 0 .. bins (the last
// repeated), as eval/interp_tables.cc's set_rows lays out its float64 rows.
void put_axis(const ProductForm& f, const std::vector<double>& pdf, int bins, std::size_t row,
              int q, float* base) {
  std::vector<internal::AxisTerms<double>> terms;
  internal::axis_terms(f, pdf, &terms);
  const std::size_t lane = std::size_t(q / kGroup) * kGroupTerms + std::size_t(q % kGroup);
  for (int i = 0; i <= bins; ++i) {
    const internal::AxisTerms<double>& a = terms[std::size_t(std::min(i, bins - 1))];
    float* t = base + std::size_t(i) * row + lane;
    t[0] = float(a.g);
    t[kGroup] = float(a.w);
    t[2 * kGroup] = float(a.y);
  }
}

// The bin values of the components without the product form, as the evaluator's table forms
// them (ModelEvaluator::table, in stored units, times the channel's scale), from a copy of the
// model that holds only them; every bin is marked measured.
std::vector<float> generic_values(Model generic_only) {
  generic_only.not_measured = NotMeasured{};
  const BrdfTable gt = ModelEvaluator(std::move(generic_only)).table();
  std::vector<float> g(kChannels * kBinsPerChannel);
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      g[i * kChannels + std::size_t(c)] = float(gt.physical(c, i));
    }
  }
  return g;
}

// The residual layer's value of every bin, channels interleaved.
std::vector<float> residual_values(const Residual& res) {
  std::vector<float> r(kChannels * kBinsPerChannel);
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      double x;
      if (res.exact) {
        x = res.exact->measured(c, i) ? res.exact->physical(c, i) : 0.0;
      } else {
        x = res.value_at(std::size_t(c) * kBinsPerChannel + i);
      }
      r[i * kChannels + std::size_t(c)] = float(x);
    }
  }
  return r;
}

}  // namespace

GpuTables gpu_tables(const Model& model) {
  GpuTables out;
  // The tables: header, slice of each theta_d bin, descriptors, then each slice's rows.
  const std::size_t ns = model.slices.size();
  std::vector<float>& t = out.tables;
  // Every section starts at a multiple of 4 floats, so that a shader reads a group's g, w or y
  // of 4 slots as one RGBA texel (rows are 12 G floats, constants 28 G).
  t.assign((std::size_t(kHeader + kThetaDBins) + kSliceDescriptor * ns + 3) / 4 * 4, 0.0f);
  bool any_generic = false;
  Model generic_only = model;  // the components without the product form (all others zeroed)
  generic_only.residual = Residual{};
  for (std::size_t s = 0; s < ns; ++s) {
    const Slice& slice = model.slices[s];
    int R = 1;
    for (const ChannelSlice& cs : slice.channel) R = std::max(R, cs.components());
    const int G = (3 * R + kGroup - 1) / kGroup;
    const std::size_t row = std::size_t(G) * kGroupTerms;
    const std::size_t off_h = t.size(), off_d = off_h + 91 * row;
    const std::size_t off_p = off_d + std::size_t(slice.width() + 1) * row;
    const std::size_t off_k = off_p + 181 * row;
    t.resize(off_k + std::size_t(G) * kGroupConstants, 0.0f);
    const float desc[kSliceDescriptor] = {float(slice.theta_d_begin),
                                          float(slice.theta_d_end),
                                          float(R),
                                          float(G),
                                          float(off_h),
                                          float(off_d),
                                          float(off_p),
                                          float(off_k)};
    std::copy(desc, desc + kSliceDescriptor,
              t.begin() + std::ptrdiff_t(kHeader + kThetaDBins + kSliceDescriptor * s));
    // Zero slots: k = 0 and 1 - h = 1 + h = 1.
    for (int q = 0; q < G * kGroup; ++q) {
      float* k = t.data() + off_k + std::size_t(q / kGroup) * kGroupConstants + (q % kGroup);
      k[kGroup] = 1.0f;
      k[4 * kGroup] = 1.0f;
    }
    for (int c = 0; c < kChannels; ++c) {
      const ChannelSlice& cs = slice.channel[std::size_t(c)];
      for (int r = 0; r < cs.components(); ++r) {
        const Component& comp = cs.component(r);
        const int q = c * R + r;
        const ProductForm f = internal::product_form(comp);
        if (!f.ok) {
          any_generic = true;
          continue;
        }
        generic_only.slices[s].channel[std::size_t(c)].component(r).scale = 0.0;
        if (comp.scale == 0.0) continue;
        float* k = t.data() + off_k + std::size_t(q / kGroup) * kGroupConstants + (q % kGroup);
        const double kv[7] = {f.k.k, f.k.a0, f.k.a1, f.k.a2, f.k.b0, f.k.b1, f.k.b2};
        for (int e = 0; e < 7; ++e) k[e * kGroup] = float(kv[e]);
        put_axis(f, comp.pdf_h, kThetaHBins, row, q, t.data() + off_h);
        put_axis(f, comp.pdf_d, slice.width(), row, q, t.data() + off_d);
        put_axis(f, comp.pdf_p, kPhiDBins, row, q, t.data() + off_p);
      }
    }
  }
  for (int j = 0; j < kThetaDBins; ++j) t[std::size_t(kHeader + j)] = float(model.slice_of(j));
  const Residual& res = model.residual;
  t[0] = float(kGpuTablesLayout);
  t[1] = float(ns);
  t[2] = !res.present() ? 0.0f : (res.exact ? 2.0f : 1.0f);
  t[3] = float(res.knee);
  t[4] = any_generic ? 1.0f : 0.0f;

  if (any_generic) out.generic = generic_values(std::move(generic_only));
  if (res.present()) out.residual = residual_values(res);
  return out;
}

std::vector<double> copula_density_plane(const Component& c, int j) {
  if (j < 0 || std::size_t(j) >= c.pdf_d.size()) return {};
  std::vector<double> out(std::size_t(kThetaHBins) * kPhiDBins, 1.0);
  const double theta =
      std::clamp(c.theta, -internal::kMaxEvaluatedParameter, internal::kMaxEvaluatedParameter);
  auto grid = internal::make_evaluation_grid(c.family, theta);
  if (!grid) return out;  // independence: a density of 1
  std::vector<double> u1, u2, u3;
  internal::midpoint_cdf(c.pdf_h, &u1);
  internal::midpoint_cdf(c.pdf_d, &u2);
  internal::midpoint_cdf(c.pdf_p, &u3);
  grid->prepare(theta, u1, u2, u3);
  for (int i = 0; i < kThetaHBins; ++i) {
    for (int k = 0; k < kPhiDBins; ++k) {
      out[std::size_t(i) * kPhiDBins + std::size_t(k)] = grid->density(i, j, k);
    }
  }
  return out;
}

}  // namespace cbrdf
