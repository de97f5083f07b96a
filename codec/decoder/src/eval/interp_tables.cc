// SPDX-License-Identifier: MIT
// InterpTables' tables, built once per model: per slice, channel and component the axis terms and
// slot constants of the product form (interp_tables.h), the generic terms' grid copulas, and the
// batch's views (eval_internal.h). Evaluation: scalar_eval.cc and batch_dispatch.cc.
// Compiled as every evaluator file: no errno from math functions, no FMA contraction
// (eval_internal.h; the pragma for GCC, CMakeLists.txt for every compiler).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("no-math-errno", "no-trapping-math", "fp-contract=off")
#endif
#include "eval/interp_tables.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <memory>
#include <mutex>
#include <numbers>
#include <type_traits>
#include <utility>
#include <vector>

#include "density/grid_copula.h"
#include "eval/eval_internal.h"
#include "eval/product_form.h"

namespace cbrdf::internal {

namespace {

// Slot q's constants in a slice's grouped array.
void set_constants(SliceTables<double>* st, int q, const SlotConstants<double>& k) {
  double* c = st->consts.data() + constant_offset(q);
  const double v[7] = {k.k, k.a0, k.a1, k.a2, k.b0, k.b1, k.b2};
  for (int e = 0; e < 7; ++e) c[e * kGroup] = v[e];
}

// Slot q's terms on one axis into its rows (row length n): bins 0 .. bins, the last repeated.
void set_rows(const std::vector<AxisTerms<double>>& terms, int bins, std::size_t n, int q,
              std::vector<double>* rows) {
  for (int i = 0; i <= bins; ++i) {
    const AxisTerms<double>& a = terms[std::size_t(std::min(i, bins - 1))];
    double* t = rows->data() + std::size_t(i) * n + term_offset(q);
    t[0] = a.g;
    t[kGroup] = a.w;
    t[2 * kGroup] = a.y;
  }
}

}  // namespace

template <class T>
std::size_t SliceTables<T>::bytes() const {
  return sizeof(*this) +
         (h.capacity() + d.capacity() + p.capacity() + consts.capacity()) * sizeof(T);
}
template struct SliceTables<double>;
template struct SliceTables<float>;

GenericTerm::GenericTerm() = default;
GenericTerm::GenericTerm(GenericTerm&&) noexcept = default;
GenericTerm& GenericTerm::operator=(GenericTerm&&) noexcept = default;
GenericTerm::~GenericTerm() = default;

double GenericTerm::value(int i, int j, int k) const {
  const Component& cs = *component;
  const double f = cs.pdf_h[std::size_t(i)] * cs.pdf_d[std::size_t(j)] * cs.pdf_p[std::size_t(k)];
  if (f == 0.0 || cs.scale == 0.0) return 0.0;
  return saturate(cs.scale * copula->density(i, j, k) * f);
}

// A slice's generic sums: 3 channels per bin, bin (i, jl, k) at ((jl * kThetaHBins + i) *
// kPhiDBins + k) * 3; NaN until computed (a sum is never NaN: every term is saturated).
struct InterpTables::GenericStore {
  std::once_flag once;
  std::atomic<bool> ready{false};
  std::unique_ptr<std::atomic<double>[]> v;
};

void InterpTables::generic_bin(std::size_t s, int i, int jl, int k, double out[3]) const {
  GenericStore& g = generic_store_[s];
  if (!g.ready.load(std::memory_order_acquire)) {
    std::call_once(g.once, [&] {
      const std::size_t n = std::size_t(kThetaHBins) *
                            std::size_t(f64_[s].theta_d_end - f64_[s].theta_d_begin) * kPhiDBins *
                            kChannels;
      g.v.reset(new std::atomic<double>[n]);
      for (std::size_t e = 0; e < n; ++e) {
        g.v[e].store(std::numeric_limits<double>::quiet_NaN(), std::memory_order_relaxed);
      }
      generic_store_bytes_.fetch_add(n * sizeof(double), std::memory_order_relaxed);
      g.ready.store(true, std::memory_order_release);
    });
  }
  std::atomic<double>* e =
      g.v.get() +
      ((std::size_t(jl) * kThetaHBins + std::size_t(i)) * kPhiDBins + std::size_t(k)) * kChannels;
  // Relaxed: two threads that miss the same bin compute and store the same values.
  bool known = true;
  for (int c = 0; c < kChannels; ++c) {
    out[c] = e[c].load(std::memory_order_relaxed);
    known = known && !(out[c] != out[c]);
  }
  if (known) return;
  out[0] = out[1] = out[2] = 0.0;
  for (const GenericTerm& t : generic_[s]) out[t.channel] += t.value(i, jl, k);
  for (int c = 0; c < kChannels; ++c) e[c].store(out[c], std::memory_order_relaxed);
}

InterpTables::InterpTables(const Model& model) {
  for (int j = 0; j < kThetaDBins; ++j) slice_of_bin_[j] = model.slice_of(j);
  const std::size_t ns = model.slices.size();
  f64_.resize(ns);
  f32_.resize(ns);
  generic_.resize(ns);
  generic_store_ = std::make_unique<GenericStore[]>(ns);
  std::vector<AxisTerms<double>> th, td, tp;
  for (std::size_t s = 0; s < ns; ++s) {
    const Slice& slice = model.slices[s];
    SliceTables<double>& st = f64_[s];
    st.theta_d_begin = slice.theta_d_begin;
    st.theta_d_end = slice.theta_d_end;
    int R = 1;
    for (const ChannelSlice& cs : slice.channel) R = std::max(R, cs.components());
    st.slots_per_channel = R;
    max_slots_per_channel_ = std::max(max_slots_per_channel_, R);
    const int width = slice.width();
    st.groups = (3 * R + kGroup - 1) / kGroup;
    const std::size_t n = st.row();
    st.h.assign(std::size_t(kThetaHBins + 1) * n, 0.0);
    st.d.assign(std::size_t(width + 1) * n, 0.0);
    st.p.assign(std::size_t(kPhiDBins + 1) * n, 0.0);
    st.consts.assign(std::size_t(st.groups) * kGroupConstants, 0.0);
    // Zero slots (and the padding): k = g = 0 and 1 - h = 1 + h = 1, a value of 0.
    for (int q = 0; q < st.groups * kGroup; ++q) set_constants(&st, q, {0, 1, 0, 0, 1, 0, 0});
    for (int c = 0; c < kChannels; ++c) {
      const ChannelSlice& cs = slice.channel[std::size_t(c)];
      for (int r = 0; r < cs.components(); ++r) {
        const Component& comp = cs.component(r);
        const int q = c * R + r;
        const ProductForm f = product_form(comp);
        if (!f.ok) {
          GenericTerm g;
          g.component = &comp;
          g.channel = c;
          const double theta =
              std::clamp(comp.theta, -kMaxEvaluatedParameter, kMaxEvaluatedParameter);
          g.copula = internal::make_evaluation_grid(comp.family, theta);
          std::vector<double> u1, u2, u3;
          internal::midpoint_cdf(comp.pdf_h, &u1);
          internal::midpoint_cdf(comp.pdf_d, &u2);
          internal::midpoint_cdf(comp.pdf_p, &u3);
          g.copula->prepare_density(theta, u1, u2, u3);
          generic_[s].push_back(std::move(g));
          any_generic_ = true;
          continue;  // its slot stays zero
        }
        if (comp.scale == 0.0) continue;
        st.product = true;
        set_constants(&st, q, f.k);
        axis_terms(f, comp.pdf_h, &th);
        axis_terms(f, comp.pdf_d, &td);
        axis_terms(f, comp.pdf_p, &tp);
        set_rows(th, kThetaHBins, n, q, &st.h);
        set_rows(td, width, n, q, &st.d);
        set_rows(tp, kPhiDBins, n, q, &st.p);
      }
    }
    SliceTables<float>& sf = f32_[s];
    sf.theta_d_begin = st.theta_d_begin;
    sf.theta_d_end = st.theta_d_end;
    sf.slots_per_channel = R;
    sf.product = st.product;
    sf.groups = st.groups;
    auto cast_all = [](const std::vector<double>& from, std::vector<float>* to) {
      to->resize(from.size());
      for (std::size_t i = 0; i < from.size(); ++i) (*to)[i] = float(from[i]);
    };
    cast_all(st.h, &sf.h);
    cast_all(st.d, &sf.d);
    cast_all(st.p, &sf.p);
    cast_all(st.consts, &sf.consts);
  }
  for (int j = 0; j < kThetaDBins; ++j)
    last_in_slice_[j] = j + 1 >= f64_[std::size_t(slice_of_bin_[j])].theta_d_end;
  prepare_batch();
}

// eval_batch's views of the slices and rows of the bins.
void InterpTables::prepare_batch() {
  const std::size_t ns = f64_.size();
  batch_ = std::make_unique<BatchViews>();
  BatchViews& bv = *batch_;
  auto view = [](const auto& st) {
    using T = typename std::decay_t<decltype(st.h)>::value_type;
    return SliceView<T>{st.h.data(), st.d.data(), st.p.data(),         st.consts.data(),
                        st.row(),    st.groups,   st.slots_per_channel};
  };
  for (std::size_t s = 0; s < ns; ++s) {
    bv.f64.push_back(view(f64_[s]));
    bv.f32.push_back(view(f32_[s]));
    bv.uniform = bv.uniform && f64_[s].groups == 1 && f64_[s].slots_per_channel == 1;
  }
  for (int j = 0; j < kThetaDBins; ++j) {
    const SliceTables<double>& st = f64_[std::size_t(slice_of_bin_[j])];
    bv.bins.slice[j] = slice_of_bin_[j];
    bv.bins.d[j] = (j - st.theta_d_begin) * int(st.row());
    bv.bins.last[j] = last_in_slice_[j];
  }
}

InterpTables::~InterpTables() = default;

std::size_t InterpTables::footprint_bytes() const {
  std::size_t n = sizeof(*this) + sizeof(BatchViews) +
                  batch_->f64.capacity() * sizeof(batch_->f64[0]) +
                  batch_->f32.capacity() * sizeof(batch_->f32[0]);
  for (const auto& s : f64_) n += s.bytes();
  for (const auto& s : f32_) n += s.bytes();
  n += generic_store_bytes_.load(std::memory_order_relaxed) + f64_.size() * sizeof(GenericStore);
  for (const auto& gs : generic_) {
    n += gs.capacity() * sizeof(GenericTerm);
    for (const GenericTerm& g : gs) {
      // The grid's prepared per-axis arrays: an Archimedean grid prepared for values holds four
      // arrays per axis (generic terms are never FrankGrid).
      const std::size_t bins =
          g.component->pdf_h.size() + g.component->pdf_d.size() + g.component->pdf_p.size();
      n += 4 * bins * sizeof(double) + 256;
    }
  }
  return n;
}

}  // namespace cbrdf::internal
