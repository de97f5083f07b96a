// SPDX-License-Identifier: MIT
// What the browser viewer (viewer/) uploads to the GPU to evaluate a model in a fragment shader:
// the evaluator's float32 tables (ModelEvaluator::eval_f32's, eval/interp_tables.h) as flat
// float32 arrays, plus two optional MERL-grid volumes (the terms without a product form, and the
// residual layer), and the file's facts as JSON. Exported from cbrdf.wasm beside the C API; the
// layout below is what viewer/shaders.mjs reads.
//
// "tables" (float32; integers are exact, all below 2^24):
//   [0] layout version (1)   [1] slices S   [2] volume mode: 0 none, 1 residual (log1p units),
//   2 the exact table (lossless residual: physical values replace the model)   [3] the residual's
//   knee (stored units)   [4] 1 when the "generic" volume holds terms   [5..15] 0
//   [16 + j], j < 90: the slice of theta_d bin j
//   [106 + 8 s ..]: slice s: theta_d begin, end, R (slots per channel), G (groups of 4 slots),
//     and the offsets (into this array) of its theta_h rows (91), theta_d rows (width + 1),
//     phi_d rows (181) and constants (G x 28), each a multiple of 4 (zeros pad the header).
//   A row is G groups of 12: the g of 4 slots, their w, their y; slot q = channel R + component
//   sits in group q / 4 at lane q % 4. Constants per group: k, a0, a1, a2, b0, b1, b2, 4 lanes
//   each. Value of a slot at interpolated terms: k g1 g2 g3 (b0 + b1 Y + b2 W) / (a0 + a1 Y +
//   a2 W)^3 with W = w1 w2 w3, Y = y1 + w1 y2 + w1 w2 y3 (interp_tables.h).
// "generic" and "residual" (float32, 3 x 90 x 90 x 180): RGB interleaved per MERL bin, bin
//   index (theta_h 90 + theta_d) 180 + phi_d; "generic" the physical values of the components
//   without the product form (Clayton, Gumbel, Joe, Frank below -200) summed per bin, "residual"
//   the residual layer's value per bin (log1p units) or, in mode 2, the exact table's physical
//   values with 0 at bins not measured.
//
// The tables are built as eval/interp_tables.cc builds its float64 ones, then rounded to float as
// it does for eval_f32: the same product form, midpoint CDFs and terms. The viewer's browser test
// (tests/viewer) compares the shader with the native eval_f32, so a divergence fails there.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <new>
#include <span>
#include <string>
#include <vector>

#include "cbrdf/codec.h"
#include "cbrdf/container.h"
#include "cbrdf/model.h"
#include "density/grid_copula.h"
#include "eval/product_form.h"

namespace {

using namespace cbrdf;

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

void append_json_string(std::string* out, const std::string& s) {
  *out += '"';
  for (const char ch : s) {
    if (ch == '"' || ch == '\\') {
      *out += '\\';
      *out += ch;
    } else if (static_cast<unsigned char>(ch) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned char>(ch));
      *out += buf;
    } else {
      *out += ch;
    }
  }
  *out += '"';
}

}  // namespace

// What cbrdf_viewer_open builds; the arrays are read in place by the page.
struct cbrdf_viewer {
  std::vector<float> arrays[3];  // tables, generic, residual
  std::string facts;             // JSON
  Model model;                   // for cbrdf_viewer_slice
};

#define CBRDF_WASM_EXPORT extern "C" __attribute__((visibility("default"), used))

// Builds the viewer's arrays from a .cbrdf file in memory; NULL when the file does not decode
// (the page opens every file with cbrdf_model_open_memory first, which reports why).
CBRDF_WASM_EXPORT cbrdf_viewer* cbrdf_viewer_open(const void* data, std::size_t size) {
  if (data == nullptr) return nullptr;
  ContainerInfo info;
  auto decoded = decode_model(
      std::span<const std::uint8_t>(static_cast<const std::uint8_t*>(data), size), &info);
  if (!decoded.ok()) return nullptr;
  const Model& model = decoded.value();
  auto v = std::unique_ptr<cbrdf_viewer>(new (std::nothrow) cbrdf_viewer);
  if (!v) return nullptr;

  // The tables: header, slice of each theta_d bin, descriptors, then each slice's rows.
  const std::size_t ns = model.slices.size();
  std::vector<float>& t = v->arrays[0];
  // Every section starts at a multiple of 4 floats, so that the page reads a group's g, w or y
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
  t[0] = 1.0f;
  t[1] = float(ns);
  t[2] = !res.present() ? 0.0f : (res.exact ? 2.0f : 1.0f);
  t[3] = float(res.knee);
  t[4] = any_generic ? 1.0f : 0.0f;

  if (any_generic) {
    // Their bin values, as the evaluator's table forms them (ModelEvaluator::table, in stored
    // units, times the channel's scale), from a copy of the model that holds only them and marks
    // every bin measured.
    generic_only.not_measured = NotMeasured{};
    const BrdfTable gt = ModelEvaluator(std::move(generic_only)).table();
    std::vector<float>& g = v->arrays[1];
    g.resize(kChannels * kBinsPerChannel);
    for (int c = 0; c < kChannels; ++c) {
      for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
        g[i * kChannels + std::size_t(c)] = float(gt.physical(c, i));
      }
    }
  }
  if (res.present()) {
    std::vector<float>& r = v->arrays[2];
    r.resize(kChannels * kBinsPerChannel);
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
  }

  // Facts: chunks, settings, evaluator footprint.
  v->model = std::move(decoded.value());
  const ModelEvaluator evaluator(
      std::shared_ptr<const Model>(std::shared_ptr<const Model>(), &v->model));
  std::string& j = v->facts;
  char buf[1024];
  std::snprintf(buf, sizeof buf,
                "{\"version\":\"%u.%u\",\"fileBytes\":%llu,\"bits\":%d,\"footprintBytes\":%zu,"
                "\"gpuTableBytes\":%zu,\"residualMode\":%d,\"residualMaxError\":%.17g,"
                "\"residualMinError\":%.17g,\"residualKnee\":%.17g,\"residualEscapes\":%zu,"
                "\"notMeasuredBins\":%zu,\"chunks\":[",
                unsigned(info.layout.major), unsigned(info.layout.minor),
                static_cast<unsigned long long>(info.layout.file_bytes), info.bits,
                evaluator.footprint_bytes(),
                (v->arrays[0].size() + v->arrays[1].size() + v->arrays[2].size()) * sizeof(float),
                info.residual_mode, info.residual_max_error, info.residual_min_error,
                info.residual_knee, info.residual_escapes, info.not_measured_bins);
  j += buf;
  for (std::size_t i = 0; i < info.layout.chunks.size(); ++i) {
    const ChunkInfo& c = info.layout.chunks[i];
    j += i ? ",{\"tag\":" : "{\"tag\":";
    append_json_string(&j, c.tag);
    std::snprintf(buf, sizeof buf,
                  ",\"offset\":%llu,\"storedBytes\":%u,\"payloadBytes\":%u,\"compressed\":%s}",
                  static_cast<unsigned long long>(c.offset), unsigned(c.stored_bytes),
                  unsigned(c.payload_bytes), c.compressed ? "true" : "false");
    j += buf;
  }
  j += "]}";
  return v.release();
}

// Array `which` (0 tables, 1 generic, 2 residual): its first float, and its length in *count
// (0 and NULL when absent).
CBRDF_WASM_EXPORT const float* cbrdf_viewer_array(const cbrdf_viewer* v, int which,
                                                  std::size_t* count) {
  if (v == nullptr || which < 0 || which > 2) {
    if (count) *count = 0;
    return nullptr;
  }
  const std::vector<float>& a = v->arrays[which];
  if (count) *count = a.size();
  return a.empty() ? nullptr : a.data();
}

// The marginals and copula of one slice and channel (its first component), for the page's slice
// plot: out[0..89] the theta_h masses, out[90..269] the phi_d masses, out[270..359] the theta_d
// masses (the slice's width of them, then 0), out[360 + 180 i + k] the copula density at theta_h
// bin i, phi_d bin k and the slice's middle theta_d bin (the family's grid, as bin values use it).
// 16,560 floats. Returns the slice's width, or -1 for a slice or channel out of range.
CBRDF_WASM_EXPORT int cbrdf_viewer_slice(const cbrdf_viewer* v, int slice, int channel,
                                         float* out) {
  if (v == nullptr || out == nullptr || slice < 0 || slice >= int(v->model.slices.size()) ||
      channel < 0 || channel >= kChannels) {
    return -1;
  }
  const Slice& sl = v->model.slices[std::size_t(slice)];
  const Component& c = sl.channel[std::size_t(channel)];
  std::fill(out, out + 16560, 0.0f);
  for (int i = 0; i < kThetaHBins; ++i) out[i] = float(c.pdf_h[std::size_t(i)]);
  for (int k = 0; k < kPhiDBins; ++k) out[90 + k] = float(c.pdf_p[std::size_t(k)]);
  for (int j = 0; j < sl.width(); ++j) out[270 + j] = float(c.pdf_d[std::size_t(j)]);
  const double theta =
      std::clamp(c.theta, -internal::kMaxEvaluatedParameter, internal::kMaxEvaluatedParameter);
  auto grid = internal::make_evaluation_grid(c.family, theta);
  if (!grid) {  // independence: a density of 1
    std::fill(out + 360, out + 16560, 1.0f);
    return sl.width();
  }
  std::vector<double> u1, u2, u3;
  internal::midpoint_cdf(c.pdf_h, &u1);
  internal::midpoint_cdf(c.pdf_d, &u2);
  internal::midpoint_cdf(c.pdf_p, &u3);
  grid->prepare(theta, u1, u2, u3);
  const int jm = sl.width() / 2;
  for (int i = 0; i < kThetaHBins; ++i)
    for (int k = 0; k < kPhiDBins; ++k) out[360 + 180 * i + k] = float(grid->density(i, jm, k));
  return sl.width();
}

CBRDF_WASM_EXPORT const char* cbrdf_viewer_facts(const cbrdf_viewer* v) {
  return v ? v->facts.c_str() : "";
}

CBRDF_WASM_EXPORT void cbrdf_viewer_free(cbrdf_viewer* v) {
  delete v;
}
