// SPDX-License-Identifier: MIT
// InterpTables::eval: one direction pair, the product form's terms interpolated per slice
// (interp_tables.h), the generic terms trilinear between bins. The reference the batch kernels
// (batch_dispatch.cc) equal bit for bit.
// Compiled as every evaluator file: no errno from math functions, no FMA contraction
// (eval_internal.h; the pragma for GCC, CMakeLists.txt for every compiler).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("no-math-errno", "no-trapping-math", "fp-contract=off")
#endif
#include <algorithm>
#include <cstddef>
#include <vector>

#include "eval/eval_internal.h"
#include "eval/interp_tables.h"
#include "eval/position.h"

namespace cbrdf::internal {

namespace {

// Adds weight * the slice's value at the interpolated position to rgb. The axis rows of the two
// bins around the position: h0/h1, d0/d1, p0/p1, fractions fh, fd, fp.
template <class T>
inline void add_slice(const SliceTables<T>& st, int i0, T fh, int jl0, T fd, int k0, T fp, T weight,
                      T rgb[3]) {
  const int R = st.slots_per_channel;
  const std::size_t n = st.row();
  const T* h0 = st.h.data() + std::size_t(i0) * n;
  const T* h1 = h0 + n;
  const T* d0 = st.d.data() + std::size_t(jl0) * n;
  const T* d1 = d0 + n;
  const T* p0 = st.p.data() + std::size_t(k0) * n;
  const T* p1 = p0 + n;
  const T gh = 1 - fh, gd = 1 - fd, gp = 1 - fp;
  constexpr int W_ = kGroup, Y_ = 2 * kGroup;
  for (int c = 0; c < kChannels; ++c) {
    T sum = 0;
    for (int r = 0; r < R; ++r) {
      const int q = c * R + r;
      const std::size_t o = term_offset(q);
      const T g1 = h0[o] * gh + h1[o] * fh, w1 = h0[o + W_] * gh + h1[o + W_] * fh,
              y1 = h0[o + Y_] * gh + h1[o + Y_] * fh;
      const T g2 = d0[o] * gd + d1[o] * fd, w2 = d0[o + W_] * gd + d1[o + W_] * fd,
              y2 = d0[o + Y_] * gd + d1[o + Y_] * fd;
      const T g3 = p0[o] * gp + p1[o] * fp, w3 = p0[o + W_] * gp + p1[o + W_] * fp,
              y3 = p0[o + Y_] * gp + p1[o + Y_] * fp;
      const T* k = st.consts.data() + constant_offset(q);
      const T w12 = w1 * w2, W = w12 * w3, Y = y1 + w1 * y2 + w12 * y3;
      const T omh = k[kGroup] + k[2 * kGroup] * Y + k[3 * kGroup] * W;
      const T oph = k[4 * kGroup] + k[5 * kGroup] * Y + k[6 * kGroup] * W;
      sum += k[0] * (g1 * g2 * g3) * oph / (omh * omh * omh);
    }
    rgb[c] += weight * sum;
  }
}

}  // namespace

template <class T>
void InterpTables::eval_impl(const std::vector<SliceTables<T>>& tables, const Position<T>& pos,
                             T rgb[3]) const {
  const int h0 = std::min(int(pos.h), kThetaHBins - 1);
  const int d0 = std::min(int(pos.d), kThetaDBins - 1);
  const int p0 = std::min(int(pos.p), kPhiDBins - 1);
  const T fh = pos.h - T(h0), fd = pos.d - T(d0), fp = pos.p - T(p0);
  const int s0 = slice_of_bin_[d0];
  const SliceTables<T>& st = tables[std::size_t(s0)];
  // Across the phi_d period (bin 179 to bin 0, where the CDF returns from 1 to 0) and across a
  // slice boundary (two slices' marginals and copulas), the terms are not interpolated: the value
  // is linear between the two bins' values, as trilinear interpolation has it.
  auto along_p = [&](const SliceTables<T>& sl, int jl, T fd_in, T weight) {
    if (!sl.product) return;  // zero slots only (generic terms): their value is 0
    if (p0 + 1 < kPhiDBins || fp == 0) {
      add_slice(sl, h0, fh, jl, fd_in, p0, fp, weight, rgb);
    } else {
      add_slice(sl, h0, fh, jl, fd_in, p0, T(0), weight * (1 - fp), rgb);
      add_slice(sl, h0, fh, jl, fd_in, 0, T(0), weight * fp, rgb);
    }
  };
  if (d0 + 1 < st.theta_d_end || fd == 0) {
    along_p(st, d0 - st.theta_d_begin, fd, T(1));
  } else {
    const SliceTables<T>& next = tables[std::size_t(slice_of_bin_[d0 + 1])];
    along_p(st, d0 - st.theta_d_begin, T(0), 1 - fd);
    along_p(next, d0 + 1 - next.theta_d_begin, T(0), fd);
  }
}

void InterpTables::add_generic(int i0, double fh, int j0, double fd, int k0, double fp,
                               double rgb[3]) const {
  for (int b = 0; b < 2; ++b) {
    const double wb = b ? fd : 1 - fd;
    if (wb == 0.0) continue;
    const int j = j0 + b;
    const std::size_t s = std::size_t(slice_of_bin_[j]);
    if (generic_[s].empty()) continue;
    const int jl = j - f64_[s].theta_d_begin;
    double v[3] = {0, 0, 0};
    for (int a = 0; a < 2; ++a) {
      const double wa = a ? fh : 1 - fh;
      if (wa == 0.0) continue;
      for (int e = 0; e < 2; ++e) {
        const double w = wa * (e ? fp : 1 - fp);
        if (w == 0.0) continue;
        double bin[3];
        generic_bin(s, i0 + a, jl, (k0 + e) % kPhiDBins, bin);
        for (int c = 0; c < kChannels; ++c) v[c] += w * bin[c];
      }
    }
    for (int c = 0; c < kChannels; ++c) rgb[c] += wb * v[c];
  }
}

void InterpTables::eval(const Vec3& wi, const Vec3& wo, double rgb[3]) const {
  rgb[0] = rgb[1] = rgb[2] = 0.0;
  if (!(wi.z > 0.0) || !(wo.z > 0.0)) return;
  eval_at(position(wi.x, wi.y, wi.z, wo.x, wo.y, wo.z), rgb);
}

void InterpTables::eval(const float wi[3], const float wo[3], float rgb[3]) const {
  rgb[0] = rgb[1] = rgb[2] = 0.0f;
  if (!(wi[2] > 0.0f) || !(wo[2] > 0.0f)) return;
  eval_at(position(wi[0], wi[1], wi[2], wo[0], wo[1], wo[2]), rgb);
}

void InterpTables::eval_at(const Position<double>& pos, double rgb[3]) const {
  rgb[0] = rgb[1] = rgb[2] = 0.0;
  eval_impl(f64_, pos, rgb);
  if (any_generic_) {
    const int h0 = std::min(int(pos.h), kThetaHBins - 1);
    const int d0 = std::min(int(pos.d), kThetaDBins - 1);
    const int p0 = std::min(int(pos.p), kPhiDBins - 1);
    add_generic(h0, pos.h - h0, d0, pos.d - d0, p0, pos.p - p0, rgb);
  }
  for (int c = 0; c < kChannels; ++c) rgb[c] = saturate(rgb[c]);
}

void InterpTables::eval_at(const Position<float>& pos, float rgb[3]) const {
  rgb[0] = rgb[1] = rgb[2] = 0.0f;
  eval_impl(f32_, pos, rgb);
  if (any_generic_) {
    const int h0 = std::min(int(pos.h), kThetaHBins - 1);
    const int d0 = std::min(int(pos.d), kThetaDBins - 1);
    const int p0 = std::min(int(pos.p), kPhiDBins - 1);
    double g[3] = {0, 0, 0};
    add_generic(h0, double(pos.h) - h0, d0, double(pos.d) - d0, p0, double(pos.p) - p0, g);
    for (int c = 0; c < kChannels; ++c) rgb[c] += float(g[c]);
  }
  for (int c = 0; c < kChannels; ++c) rgb[c] = saturate(rgb[c]);
}

}  // namespace cbrdf::internal
